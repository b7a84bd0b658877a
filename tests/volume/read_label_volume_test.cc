// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/volume/read_label_volume.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>

#include "core/pipeline/pipeline.h"
#include "core/volume/label_statistics.h"
#include "core/volume/phantom.h"
#include "core/volume/write_label_volume.h"
#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh::volume {
namespace {

using testing::Nifti1Bytes;

LabelVolume read_or_die(const std::string& path) {
  auto volume = read_label_volume(path, ReadLimits{}, RunContext{});
  EXPECT_THAT(volume, testing::IsOk());
  return volume.ok() ? std::move(*volume) : LabelVolume{};
}

void expect_same_geometry(const ImageGeometry& a, const ImageGeometry& b) {
  EXPECT_EQ(a.dims, b.dims);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(a.spacing[i], b.spacing[i], 1e-6);
    EXPECT_NEAR(a.origin[i], b.origin[i], 1e-5);
  }
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(a.direction[i], b.direction[i], 1e-6) << "element " << i;
}

// Every supported format keeps the oblique, anisotropic grid and every voxel.
class FormatRoundTrip : public ::testing::TestWithParam<std::string> {};

TEST_P(FormatRoundTrip, KeepsPlacementAndLabels) {
  const std::string file = GetParam();
  const bool oblique = file.find(".inr") == std::string::npos;  // INR has no direction
  const auto phantom =
      make_phantom(oblique ? PhantomShape::kObliqueEllipsoid : PhantomShape::kNestedSpheres);
  const auto dir =
      testing::scratch_dir("roundtrip-" + std::to_string(std::hash<std::string>{}(file)));
  const auto path = (dir / file).string();
  ASSERT_THAT(write_label_volume(phantom.volume, path), testing::IsOk());
  const LabelVolume read = read_or_die(path);
  expect_same_geometry(read.geometry, phantom.volume.geometry);
  const auto expected = compute_label_statistics(phantom.volume);
  const auto got = compute_label_statistics(read);
  ASSERT_EQ(got.labels.size(), expected.labels.size());
  for (size_t i = 0; i < got.labels.size(); ++i) {
    EXPECT_EQ(got.labels[i].label, expected.labels[i].label);
    EXPECT_EQ(got.labels[i].voxels, expected.labels[i].voxels);
  }
  EXPECT_EQ(got.background_voxels, expected.background_voxels);
}

INSTANTIATE_TEST_SUITE_P(Formats, FormatRoundTrip,
                         ::testing::Values("v.nii", "v.nii.gz", "v.mha", "v.mhd", "v.nrrd",
                                           "v.nhdr", "v.inr", "v.inr.gz", "v.vti"),
                         [](const auto& info) {
                           std::string name = info.param.substr(2);
                           for (char& c : name) c = c == '.' ? '_' : c;
                           return name;
                         });

TEST(ReadLabelVolume, QformWithNegativeQfacPlacesTheFirstSliceFirst) {
  // qform only, qfac = -1: VTK's reader stores the slices reversed; the
  // geometry must follow so that file voxel (0,0,0) stays where the header says.
  Nifti1Bytes n(3, 4, 5);
  n.put<int16_t>(254, 0);   // no sform
  n.put<int16_t>(252, 1);   // qform
  n.put<float>(76, -1.0f);  // qfac
  n.put<float>(80, 0.5f);
  n.put<float>(84, 0.75f);
  n.put<float>(88, 2.0f);
  n.put<float>(268, 10.0f);  // qoffset (RAS)
  n.put<float>(272, 20.0f);
  n.put<float>(276, 30.0f);
  n.voxels[0] = 7;  // file voxel (0,0,0)
  const auto dir = testing::scratch_dir("qfac");
  const auto path = (dir / "qfac.nii").string();
  testing::write_file(path, n.bytes());
  const LabelVolume volume = read_or_die(path);
  const auto stats = compute_label_statistics(volume);
  ASSERT_EQ(stats.labels.size(), 1u);
  const auto& where = stats.labels[0].min_index;
  const auto p =
      volume.geometry.to_physical({double(where[0]), double(where[1]), double(where[2])});
  // NIfTI puts file voxel (0,0,0) at the qoffset, RAS (10,20,30) = LPS (-10,-20,30).
  EXPECT_NEAR(p[0], -10.0, 1e-9);
  EXPECT_NEAR(p[1], -20.0, 1e-9);
  EXPECT_NEAR(p[2], 30.0, 1e-9);
  // and file voxel (0,0,1) one slice further along -z (qfac = -1).
  const auto next =
      volume.geometry.to_physical({double(where[0]), double(where[1]), double(where[2]) - 1});
  EXPECT_NEAR(next[2], 28.0, 1e-9);
}

TEST(ReadLabelVolume, RealValuedVolumesNeedWholeNumbers) {
  const auto dir = testing::scratch_dir("float");
  Nifti1Bytes n(2, 2, 2);
  n.put<int16_t>(70, 16);  // float32
  n.put<int16_t>(72, 32);
  std::string bytes = n.header;
  const float whole[8] = {0, 1, 1, 2, 0, 0, 3, 0};
  bytes.append(reinterpret_cast<const char*>(whole), sizeof whole);
  testing::write_file(dir / "whole.nii", bytes);
  const LabelVolume volume = read_or_die((dir / "whole.nii").string());
  EXPECT_EQ(volume.file_voxel_type, "float32");
  EXPECT_EQ(compute_label_statistics(volume).labels.size(), 3u);

  const float fractional[8] = {0, 1.5f, 1, 2, 0, 0, 3, 0};
  bytes = n.header;
  bytes.append(reinterpret_cast<const char*>(fractional), sizeof fractional);
  testing::write_file(dir / "fraction.nii", bytes);
  const auto refused =
      read_label_volume((dir / "fraction.nii").string(), ReadLimits{}, RunContext{});
  ASSERT_FALSE(refused.ok());
  EXPECT_THAT(refused, testing::StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(std::string(refused.status().message()).find("whole-number"), std::string::npos);
}

TEST(ReadLabelVolume, StopsWhenCancelled) {
  std::atomic<bool> stop{true};
  RunContext context;
  context.stop = &stop;
  const auto result =
      read_label_volume(testing::shared_data("liver.inr.gz"), ReadLimits{}, context);
  EXPECT_THAT(result, testing::StatusIs(absl::StatusCode::kCancelled));
}

// The real segmentations: dims and label voxel counts from shared/data/SOURCES.md.
struct RealVolume {
  std::string file;
  std::array<int64_t, 3> dims;
  size_t label_count;
  std::map<int32_t, uint64_t> voxels;  // a selection, 0 = background
};

class RealData : public ::testing::TestWithParam<RealVolume> {};

// Through summarise_volume(), the code behind `labelmesh info`.
TEST_P(RealData, MatchesSources) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const RealVolume& expected = GetParam();
  const auto summary =
      summarise_volume(testing::shared_data(expected.file), ReadLimits{}, RunContext{});
  ASSERT_THAT(summary, testing::IsOk());
  EXPECT_EQ(summary->geometry.dims, expected.dims);
  const auto& stats = summary->statistics;
  EXPECT_EQ(stats.labels.size(), expected.label_count);
  for (const auto& [label, voxels] : expected.voxels) {
    if (label == 0) {
      EXPECT_EQ(stats.background_voxels, voxels);
      continue;
    }
    const auto* found = stats.find(label);
    ASSERT_NE(found, nullptr) << "label " << label;
    EXPECT_EQ(found->voxels, voxels) << "label " << label;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Sources, RealData,
    ::testing::Values(
        RealVolume{"liver.inr.gz",
                   {438, 353, 329},
                   4,
                   {{0, 43882593}, {84, 6}, {85, 35274}, {127, 628131}, {255, 6322002}}},
        RealVolume{"MRIcrop-seg_converted.nii.gz",
                   {78, 110, 64},
                   8,
                   {{0, 493227},
                    {1, 18138},
                    {2, 2633},
                    {3, 4775},
                    {4, 2250},
                    {5, 2548},
                    {6, 1047},
                    {7, 7661},
                    {8, 16841}}},
        RealVolume{"vb-seg.mha",
                   {640, 633, 299},
                   8,
                   {{0, 119909106},
                    {1, 107980},
                    {2, 123730},
                    {3, 135904},
                    {4, 148775},
                    {5, 158103},
                    {6, 170319},
                    {7, 183404},
                    {8, 193559}}},
        RealVolume{
            "iso2mesh_brain_seg_converted.nii.gz",
            {256, 256, 256},
            40,
            {{0, 15397727}, {2, 259660}, {3, 273698}, {30, 99}, {81, 4}, {82, 4}, {85, 302}}},
        RealVolume{"totalseg_example_seg_dicom.nii.gz",
                   {512, 512, 20},
                   31,
                   {{0, 4503460}, {1, 130634}, {5, 366708}, {115, 288}, {117, 15441}}},
        // SOURCES.md's summary says 63 labels; its own per-label list, and
        // nibabel, hold 61.
        RealVolume{"totalseg_example_seg_fast_force_split.nii.gz",
                   {122, 101, 112},
                   61,
                   {{0, 1034076}, {1, 9668}, {5, 41692}, {33, 83}, {117, 2325}}},
        RealVolume{"totalseg_example_seg_mr.nii.gz",
                   {117, 91, 20},
                   23,
                   {{0, 168906}, {5, 18480}, {11, 6}, {49, 135}}},
        RealVolume{
            "msd_prostate_mask_00.nii", {320, 320, 15}, 2, {{0, 1503154}, {1, 5813}, {2, 27033}}},
        RealVolume{"frogtissue.mhd",
                   {500, 470, 136},
                   25,
                   {{0, 30803043}, {1, 35279}, {10, 204672}, {13, 440722}, {21, 4}, {29, 40}}}),
    [](const auto& info) {
      std::string name = info.param.file.substr(0, info.param.file.find('.'));
      for (char& c : name) c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
      return name;
    });

TEST(RealData, ObliqueProstateMatchesNibabelsAffine) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  // nibabel (independent of our parser) gives the RAS affine; ours is LPS.
  const std::string path = testing::shared_data("msd_prostate_mask_00.nii");
  const std::string command =
      "/usr/bin/python3 -c \"import nibabel, sys; a = nibabel.load(sys.argv[1]).affine; "
      "print(' '.join(repr(float(v)) for v in a[:3].ravel()))\" " +
      path;
  FILE* pipe = popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  double affine[12];
  int read = 0;
  while (read < 12 && std::fscanf(pipe, "%lf", &affine[read]) == 1) ++read;
  ASSERT_EQ(pclose(pipe), 0) << "python3-nibabel is needed (scripts/install-deps.sh)";
  ASSERT_EQ(read, 12);
  const LabelVolume volume = read_or_die(path);
  const double to_lps[3] = {-1, -1, 1};
  for (int i : {0, 7, 319}) {
    for (int k : {0, 14}) {
      const auto p = volume.geometry.to_physical({double(i), 5.0, double(k)});
      for (int row = 0; row < 3; ++row) {
        const double ras = affine[4 * row] * i + affine[4 * row + 1] * 5.0 +
                           affine[4 * row + 2] * k + affine[4 * row + 3];
        EXPECT_NEAR(p[row], to_lps[row] * ras, 1e-4) << "voxel " << i << ",5," << k;
      }
    }
  }
  EXPECT_NEAR(volume.geometry.spacing[2], 4.0, 1e-4);
}

}  // namespace
}  // namespace labelmesh::volume
