// SPDX-License-Identifier: AGPL-3.0-or-later
// The service's contract, in-process: every RPC, its status codes, and what
// the spool holds afterwards. Jobs run in real worker processes (labelmesh-worker).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <set>
#include <string>
#include <thread>
#include <tuple>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "core/job/job_options.h"
#include "core/pipeline/pipeline.h"
#include "core/pipeline/report.h"
#include "core/volume/label_volume.h"
#include "core/volume/phantom.h"
#include "core/volume/write_label_volume.h"
#include "server/event_pipe.h"
#include "server/labelmesh_server.h"
#include "server/metrics.h"
#include "server/spool.h"
#include "server/worker_process.h"
#include "server/worker_protocol.h"
#include "support/service_harness.h"
#include "support/status_matchers.h"

namespace labelmesh::testing {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// A stand-in worker script's first line: labelmeshd checks its version.
const std::string kAnswersVersion = absl::StrCat("[ \"$1\" = --version ] && { echo '",
                                                 server::kWorkerVersionLine, "'; exit 0; }\n");

// The liver's organ label (it also holds a few stray voxels of label 84).
v1::MeshOptions liver_options() {
  v1::MeshOptions options;
  options.add_labels(255);
  return options;
}

class MeshingServiceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = scratch_dir(::testing::UnitTest::GetInstance()->current_test_info()->name());
    spool_ = dir_ / "spool";
    config_ = ServiceHarness::config_for(spool_);
  }

  // The quick job most tests need: the sphere phantom, repaired surface.
  grpc::Status submit_sphere(ServiceHarness& service, v1::SubmitReply* reply) {
    return service.submit(write_phantom(dir_, volume::PhantomShape::kSphere), repaired_options(),
                          reply);
  }

  // Submits `input` with `options` and waits for the job to end.
  v1::Job finished_job(ServiceHarness& service, const fs::path& input,
                       const v1::MeshOptions& options) {
    v1::SubmitReply reply;
    EXPECT_THAT(service.submit(input, options, &reply), testing::IsOk());
    service.watch(reply.job_id());
    return service.get(reply.job_id());
  }

  size_t uploads_left() const { return count_files(spool_ / "uploads"); }
  size_t job_dirs() const {
    size_t count = 0;
    for ([[maybe_unused]] const auto& entry : fs::directory_iterator(spool_ / "jobs")) ++count;
    return count;
  }

  fs::path dir_, spool_;
  server::ServerConfig config_;
};

TEST_F(MeshingServiceTest, WholeJobFromUploadToFetchedArtifacts) {
  ServiceHarness service(config_);
  v1::SubmitReply reply;
  const fs::path input = write_phantom(dir_, volume::PhantomShape::kSphere);
  ASSERT_THAT(service.submit(input, v1::MeshOptions(), &reply), testing::IsOk());
  EXPECT_EQ(reply.job_id().size(), 32u);
  EXPECT_EQ(reply.queue_position(), 0u);

  const auto events = service.watch(reply.job_id());
  ASSERT_FALSE(events.empty());
  EXPECT_TRUE(events.front().has_queued());
  ASSERT_TRUE(events.back().has_finished()) << events.back().DebugString();
  int stages_finished = 0;
  for (size_t i = 1; i < events.size(); ++i) {
    EXPECT_GT(events[i].sequence(), events[i - 1].sequence());
    if (events[i].has_stage_finished()) ++stages_finished;
  }
  EXPECT_GE(stages_finished, 5);  // read, marching cubes, components, repair, poisson, ...
  const v1::Report& report = events.back().finished().report();
  ASSERT_EQ(report.input().labels_size(), 1);
  bool found_output = false;
  for (const auto& surface : report.surfaces()) {
    if (!surface.output()) continue;
    found_output = true;
    // By default the shared net, judged against the voxels.
    EXPECT_EQ(surface.stage(), "net");
    EXPECT_TRUE(surface.closed());
    EXPECT_TRUE(surface.fidelity().within_tolerance());
    EXPECT_EQ(surface.fidelity()
                  .attempts(surface.fidelity().attempts_size() - 1)
                  .voxels()
                  .misclassified(),
              0u);
  }
  EXPECT_TRUE(found_output);

  const v1::Job job = service.get(reply.job_id());
  EXPECT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED);
  EXPECT_EQ(job.attempts(), 1u);
  EXPECT_DOUBLE_EQ(job.progress(), 1.0);
  // The job was submitted with every option left unset; GetJob shows the
  // options it ran with, the same the report prints.
  EXPECT_EQ(job.options().DebugString(), report.options().DebugString());
  EXPECT_EQ(job.options().volume(), v1::VOLUME_METHOD_NONE);
  EXPECT_EQ(job.options().min_angle_deg(), 30);

  auto ctx = service.context();
  v1::ListArtifactsRequest list_request;
  list_request.set_job_id(reply.job_id());
  v1::ListArtifactsReply artifacts;
  ASSERT_THAT(service.stub().ListArtifacts(ctx.get(), list_request, &artifacts), testing::IsOk());
  std::vector<std::string> names;
  for (const auto& artifact : artifacts.artifacts()) names.push_back(artifact.name());
  EXPECT_EQ(names, (std::vector<std::string>{"report.html", "report.json", "surface-label1.stl",
                                             "surface-label1.vtp"}));
  for (const auto& artifact : artifacts.artifacts()) {
    auto fetch_ctx = service.context();
    v1::FetchRequest request;
    request.set_job_id(reply.job_id());
    request.set_artifact(artifact.name());
    auto reader = service.stub().Fetch(fetch_ctx.get(), request);
    v1::FetchChunk chunk;
    std::string bytes;
    int chunks = 0;
    while (reader->Read(&chunk)) {
      if (chunks++ == 0) {
        EXPECT_EQ(chunk.artifact().sha256(), artifact.sha256());
      }
      EXPECT_LE(chunk.data().size(), 1u << 20);
      bytes += chunk.data();
    }
    ASSERT_THAT(reader->Finish(), testing::IsOk());
    EXPECT_EQ(bytes.size(), artifact.size_bytes());
    EXPECT_EQ(digest::sha256_hex(bytes), artifact.sha256()) << artifact.name();
  }
  EXPECT_NE(service.server().metrics().text().find("labelmesh_jobs_total{outcome=\"succeeded\"} 1"),
            std::string::npos);
}

// A mixed volume mesh from the service is the one this process makes.
TEST_F(MeshingServiceTest, TheServiceMakesTheSameMixedMeshAsTheLibrary) {
  ServiceHarness service(config_);
  const fs::path input = write_phantom(dir_, volume::PhantomShape::kSphere);
  v1::MeshOptions options = repaired_options();
  options.set_volume(v1::VOLUME_METHOD_MIXED);
  options.set_hex_size_mm(2);
  options.add_formats("stl");
  options.add_formats("vtu");
  const v1::Job job = finished_job(service, input, options);
  ASSERT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED) << job.error().message();
  const v1::VolumeMeshSummary& served = job.report().volume();

  auto params = params_from_options(options);
  ASSERT_THAT(params, testing::IsOk());
  auto local = run_pipeline(input.string(), *params, {});
  ASSERT_THAT(local, testing::IsOk());
  const v1::VolumeMeshSummary mine = make_report(*local, *params).volume();
  EXPECT_EQ(served.mesher(), "mixed_grid");
  EXPECT_GT(served.hexahedra(), 0u);
  EXPECT_EQ(served.hexahedra(), mine.hexahedra());
  EXPECT_EQ(served.pyramids(), mine.pyramids());
  EXPECT_EQ(served.tetrahedra(), mine.tetrahedra());
  EXPECT_EQ(served.nodes(), mine.nodes());
  EXPECT_EQ(served.enclosed_volume_mm3(), mine.enclosed_volume_mm3());
  EXPECT_EQ(served.jacobian_ratio_min(), mine.jacobian_ratio_min());
  EXPECT_EQ(served.tetrahedral_layer_labels_size(), mine.tetrahedral_layer_labels_size());
  EXPECT_EQ(served.inverted(), 0u);
  EXPECT_EQ(served.files_size(), 1);
}

// Hexahedra only through the service: labels too thin for them are left out,
// no empty file is written, and the job still succeeds, saying which and why.
TEST_F(MeshingServiceTest, HexahedraOnlyJobsListTheLabelsLeftOut) {
  ServiceHarness service(config_);
  const fs::path input = write_phantom(dir_, volume::PhantomShape::kNestedSpheres);
  v1::MeshOptions options = repaired_options();
  options.set_volume(v1::VOLUME_METHOD_HEX);
  options.set_hex_size_mm(2);
  options.add_formats("vtu");
  const v1::Job job = finished_job(service, input, options);
  ASSERT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED) << job.error().message();
  const v1::VolumeMeshSummary& served = job.report().volume();
  EXPECT_EQ(served.mesher(), "hex_grid");
  // At 2 mm no label of the nested spheres keeps a valid hexahedral layer.
  EXPECT_EQ(served.hexahedra() + served.pyramids() + served.tetrahedra(), 0u);
  ASSERT_EQ(served.labels_left_out_size(), 3);
  std::set<int32_t> left_out;
  for (const auto& item : served.labels_left_out()) {
    EXPECT_FALSE(item.reason().empty());
    left_out.insert(item.label());
  }
  size_t warned = 0;
  for (const auto& warning : job.report().warnings())
    warned +=
        left_out.count(warning.label()) && absl::StartsWith(warning.reason(), "no volume mesh: ");
  EXPECT_EQ(warned, left_out.size());
  EXPECT_EQ(left_out, (std::set<int32_t>{1, 2, 3}));
  EXPECT_EQ(served.files_size(), 0);
}

TEST_F(MeshingServiceTest, ConformingJobsShareInterfacesAsInTheCli) {
  ServiceHarness service(config_);
  const fs::path input = write_phantom(dir_, volume::PhantomShape::kNestedSpheres);
  v1::MeshOptions options;
  options.set_volume(v1::VOLUME_METHOD_CONFORMING);
  options.add_formats("vtu");
  options.add_formats("msh");
  const v1::Job job = finished_job(service, input, options);
  ASSERT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED) << job.error().message();
  const v1::VolumeMeshSummary& served = job.report().volume();
  EXPECT_EQ(served.mesher(), "conforming");
  EXPECT_TRUE(served.conforming());
  // Ball, two shells: (1,2), (2,3) and (3, outside).
  EXPECT_EQ(served.conforming_figures().interfaces(), 3u);
  EXPECT_GT(served.conforming_figures().interface_faces(), 0u);
  EXPECT_EQ(served.conforming_figures().labels_size(), 3);
  EXPECT_EQ(served.inverted(), 0u);
  EXPECT_EQ(job.report().surfaces_size(), 3);

  // The same job in this process gives the same mesh.
  auto params = params_from_options(options);
  ASSERT_THAT(params, testing::IsOk());
  auto local = run_pipeline(input.string(), *params, {});
  ASSERT_THAT(local, testing::IsOk());
  const v1::VolumeMeshSummary mine = make_report(*local, *params).volume();
  EXPECT_EQ(served.tetrahedra(), mine.tetrahedra());
  EXPECT_EQ(served.nodes(), mine.nodes());
  EXPECT_EQ(served.tetra_quality_min(), mine.tetra_quality_min());
  EXPECT_EQ(served.files_size(), 3);  // volume.vtu, volume_interfaces.vtu, volume.msh
}

TEST_F(MeshingServiceTest, FullQueueRefusesWithResourceExhausted) {
  config_.workers = 0;  // Nothing starts: the queue only fills.
  config_.queue_capacity = 2;
  ServiceHarness service(config_);
  const fs::path input = write_phantom(dir_, volume::PhantomShape::kSphere);
  v1::SubmitReply reply;
  ASSERT_THAT(service.submit(input, repaired_options(), &reply), testing::IsOk());
  EXPECT_EQ(reply.queue_position(), 0u);
  ASSERT_THAT(service.submit(input, repaired_options(), &reply), testing::IsOk());
  EXPECT_EQ(reply.queue_position(), 1u);
  const grpc::Status full = service.submit(input, repaired_options(), &reply);
  EXPECT_EQ(full.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << full.error_message();
  EXPECT_EQ(job_dirs(), 2u);
  EXPECT_EQ(uploads_left(), 0u);
  EXPECT_NE(
      service.server().metrics().text().find("labelmesh_rejections_total{reason=\"queue_full\"} 1"),
      std::string::npos);
}

// A volume the size of a CT series: 400^3 one-byte voxels, 64 MB as an
// uncompressed NIfTI file, in 1 MiB chunks. It arrives whole and meshes.
TEST_F(MeshingServiceTest, UploadOverFiftyMegabytesArrivesWhole) {
  constexpr int kSide = 400, kRadius = 20;
  volume::LabelVolume big;
  big.file_voxel_type = "uint8";
  big.geometry.dims = {kSide, kSide, kSide};
  big.voxels = vtkSmartPointer<vtkImageData>::New();
  big.voxels->SetDimensions(kSide, kSide, kSide);
  big.voxels->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
  auto* voxel = static_cast<uint8_t*>(big.voxels->GetScalarPointer());
  int64_t ball_voxels = 0;
  for (int z = 0; z < kSide; ++z) {
    for (int y = 0; y < kSide; ++y) {
      for (int x = 0; x < kSide; ++x) {
        const int dx = x - 150, dy = y - 200, dz = z - 250;
        const bool inside = dx * dx + dy * dy + dz * dz <= kRadius * kRadius;
        ball_voxels += inside;
        *voxel++ = inside ? 1 : 0;
      }
    }
  }
  const fs::path input = dir_ / "big.nii";
  ASSERT_THAT(volume::write_label_volume(big, input.string()), testing::IsOk());
  ASSERT_GT(fs::file_size(input), 64'000'000u);

  ServiceHarness service(config_);
  v1::SubmitReply reply;
  ASSERT_THAT(service.submit(input, repaired_options(), &reply), testing::IsOk());
  EXPECT_EQ(uploads_left(), 0u);
  const auto events = service.watch(reply.job_id());
  ASSERT_TRUE(events.back().has_finished()) << events.back().DebugString();
  const v1::Report& report = events.back().finished().report();
  ASSERT_EQ(report.input().dims_size(), 3);
  EXPECT_EQ(report.input().dims(2), kSide);
  ASSERT_EQ(report.input().labels_size(), 1);
  EXPECT_EQ(report.input().labels(0).voxels(), ball_voxels);
}

TEST_F(MeshingServiceTest, BrokenUploadsAreRefusedAndLeaveNothing) {
  config_.max_upload_bytes = 1 << 20;
  ServiceHarness service(config_);
  const std::string bytes = read_bytes(write_phantom(dir_, volume::PhantomShape::kSphere));
  v1::JobSpec good;
  good.set_file_name("scan.nii.gz");
  good.set_size_bytes(bytes.size());
  good.set_sha256(digest::sha256_hex(bytes));
  v1::SubmitReply reply;
  auto expect_invalid = [&](const v1::JobSpec& spec, const std::string& sent,
                            const std::string& fragment) {
    const grpc::Status status = service.submit_raw(spec, sent, &reply);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << fragment;
    EXPECT_TRUE(absl::StrContains(status.error_message(), fragment)) << status.error_message();
  };

  v1::JobSpec wrong_digest = good;
  wrong_digest.set_sha256(digest::sha256_hex("something else"));
  expect_invalid(wrong_digest, bytes, "SHA-256");
  expect_invalid(good, bytes.substr(0, bytes.size() / 2), "truncated");
  v1::JobSpec too_small = good;
  too_small.set_size_bytes(bytes.size() - 1);
  expect_invalid(too_small, bytes, "more bytes than spec.size_bytes");
  v1::JobSpec oversize = good;
  oversize.set_size_bytes(2 << 20);
  expect_invalid(oversize, bytes, "upload limit");
  v1::JobSpec detached = good;
  detached.set_file_name("scan.mhd");
  expect_invalid(detached, bytes, "spec.file_name");
  // A NRRD or MetaImage header naming a separate data file is refused the
  // same way whether or not that file exists beside the upload (in the
  // spool's uploads directory): uploads cannot probe the server's disk.
  const fs::path existing = spool_ / "uploads" / "existing.raw";
  write_file(existing, std::string(8, '\1'));
  for (const std::string data_file : {"existing.raw", "no-such-file.raw"}) {
    const std::string nrrd = absl::StrCat(
        "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\ndata file: ", data_file,
        "\n\n");
    const std::string mha = absl::StrCat(
        "ObjectType = Image\nNDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\n"
        "ElementDataFile = ",
        data_file, "\n");
    for (const auto& [name, header, field] :
         {std::tuple{"scan.nrrd", nrrd, "data file"}, {"scan.mha", mha, "ElementDataFile"}}) {
      v1::JobSpec spec = good;
      spec.set_file_name(name);
      spec.set_size_bytes(header.size());
      spec.set_sha256(digest::sha256_hex(header));
      expect_invalid(spec, header,
                     absl::StrCat("upload: ", field, ": a separate data file is not accepted"));
    }
  }
  fs::remove(existing);
  v1::JobSpec bad_option = good;
  bad_option.mutable_options()->set_min_angle_deg(45);
  expect_invalid(bad_option, bytes, "spec.options");
  // Point counts out of range: the refusal names the field.
  auto expect_bad_option = [&](auto set, const std::string& field) {
    v1::JobSpec spec = good;
    set(*spec.mutable_options());
    expect_invalid(spec, bytes, field);
  };
  expect_bad_option([](v1::MeshOptions& o) { o.set_point_cluster_size(0); }, "point_cluster_size");
  expect_bad_option([](v1::MeshOptions& o) { o.set_max_points(10); }, "max_points");
  expect_bad_option([](v1::MeshOptions& o) { o.set_split_points(10); }, "split_points");
  // Bytes that are not a NIfTI file: our header check names the file "upload".
  const std::string garbage(4096, 'x');
  v1::JobSpec not_nifti = good;
  not_nifti.set_file_name("scan.nii");
  not_nifti.set_size_bytes(garbage.size());
  not_nifti.set_sha256(digest::sha256_hex(garbage));
  expect_invalid(not_nifti, garbage, "upload");
  // A chunk over 1 MiB.
  const std::string big(1536 << 10, '\0');
  v1::JobSpec big_spec = good;
  big_spec.set_size_bytes(big.size());
  big_spec.set_sha256(digest::sha256_hex(big));
  config_.max_upload_bytes = 4 << 20;
  EXPECT_EQ(service.submit_raw(big_spec, big, &reply, big.size()).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);

  EXPECT_EQ(uploads_left(), 0u);
  EXPECT_EQ(job_dirs(), 0u);
  // The refusals cost the server nothing: a good upload still goes through.
  EXPECT_THAT(service.submit_raw(good, bytes, &reply), testing::IsOk());
}

// Refused at Submit, not later in a worker: a volume a worker cannot hold,
// a gzip stream whose CRC is wrong under a size trailer that looks right,
// sizing the voxels cannot tell apart, and a spec of 250,000 formats.
TEST_F(MeshingServiceTest, UploadsThatCouldOnlyFailLaterAreRefusedAtSubmit) {
  config_.worker_memory_bytes = 64 << 10;
  ServiceHarness service(config_);
  const fs::path sphere = write_phantom(dir_, volume::PhantomShape::kSphere);
  v1::SubmitReply reply;
  grpc::Status status = service.submit(sphere, repaired_options(), &reply);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_TRUE(absl::StrContains(status.error_message(), "worker limit")) << status.error_message();
  service.shutdown();

  config_.worker_memory_bytes = ServiceHarness::config_for(spool_).worker_memory_bytes;
  ServiceHarness roomy(config_);
  std::string damaged = read_bytes(sphere);
  damaged[damaged.size() - 8] ^= 0x5a;  // the gzip CRC32, before ISIZE
  const fs::path wrong_crc = dir_ / "wrong-crc.nii.gz";
  write_file(wrong_crc, damaged);
  status = roomy.submit(wrong_crc, repaired_options(), &reply);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_TRUE(absl::StrContains(status.error_message(), "upload: compressed voxel data"))
      << status.error_message();

  v1::MeshOptions dicom = repaired_options();
  dicom.add_formats("dcm");
  status = roomy.submit(sphere, dicom, &reply);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_TRUE(absl::StrContains(status.error_message(), "dcm needs a DICOM SEG upload"))
      << status.error_message();

  v1::MeshOptions fine = repaired_options();
  fine.set_max_edge_mm(0.01);
  status = roomy.submit(sphere, fine, &reply);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_TRUE(absl::StrContains(status.error_message(), "max_edge_mm")) << status.error_message();

  v1::MeshOptions many = repaired_options();
  for (int i = 0; i < 250000; ++i) many.add_formats("off");
  status = roomy.submit(sphere, many, &reply);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_TRUE(absl::StrContains(status.error_message(), "formats")) << status.error_message();

  // VTK XML: the compressed appended array cut short, closing tags kept, so
  // that the header passes and only reading the array finds it.
  const fs::path vti = dir_ / "sphere.vti";
  ASSERT_TRUE(volume::write_label_volume(
                  volume::make_phantom(volume::PhantomShape::kSphere, 1.0).volume, vti.string())
                  .ok());
  const std::string whole = read_bytes(vti);
  const size_t data = whole.find('_', whole.find("<AppendedData"));
  ASSERT_NE(data, std::string::npos);
  const fs::path cut_vti = dir_ / "cut.vti";
  write_file(cut_vti, whole.substr(0, data + (whole.size() - data) / 2) +
                          "\n  </AppendedData>\n</VTKFile>\n");
  status = roomy.submit(cut_vti, repaired_options(), &reply);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << status.error_message();
  EXPECT_FALSE(absl::StrContains(status.error_message(), spool_.string()))
      << status.error_message();

  EXPECT_EQ(job_dirs(), 0u);
  EXPECT_EQ(uploads_left(), 0u);
  EXPECT_THAT(roomy.submit(sphere, repaired_options(), &reply), testing::IsOk());
  EXPECT_THAT(roomy.submit(vti, repaired_options(), &reply), testing::IsOk());
}

// DICOM SEG: read whole in a worker at Submit, so what cannot be meshed
// (segments that overlap, no patient geometry) is refused before it queues,
// and what can comes back with its segments' names.
TEST_F(MeshingServiceTest, ADicomSegIsMeshedWithItsSegmentNamesOrRefusedAtSubmit) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  ServiceHarness service(config_);
  v1::SubmitReply reply;
  for (const char* refused : {"dicom-seg/highdicom-seg_image_ct_binary_overlap.dcm",
                              "dicom-seg/highdicom-seg_image_cr_binary.dcm"}) {
    const grpc::Status status = service.submit(shared_data(refused), repaired_options(), &reply);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << refused;
    EXPECT_TRUE(absl::StartsWith(status.error_message(), "upload: ")) << status.error_message();
  }
  EXPECT_EQ(job_dirs(), 0u);
  EXPECT_EQ(uploads_left(), 0u);

  ASSERT_TRUE(
      service.submit(shared_data("dicom-seg/dcmqi-24x38x3-seg.dcm"), repaired_options(), &reply)
          .ok());
  const auto events = service.watch(reply.job_id());
  const v1::Job job = service.get(reply.job_id());
  ASSERT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED) << job.error().message();
  const v1::InputSummary& input = job.report().input();
  EXPECT_EQ(input.format(), "dicom-seg");
  ASSERT_EQ(input.labels_size(), 1);
  EXPECT_EQ(input.labels(0).name(), "Liver");
  EXPECT_EQ(input.labels(0).voxels(), 315u);
  EXPECT_EQ(input.labels(0).type().value(), "T-62000");
  EXPECT_EQ(input.layers(), 1u);
  // Progress of the label-by-label stages names the segment; every stage
  // starts and finishes once.
  std::set<std::string> started, finished;
  int named = 0;
  for (const auto& event : events) {
    if (event.has_stage_started()) {
      EXPECT_TRUE(started.insert(event.stage_started().stage()).second);
    }
    if (event.has_stage_finished()) {
      EXPECT_TRUE(finished.insert(event.stage_finished().stage()).second);
    }
    if (event.has_progress() && event.progress().label() != 0) {
      ++named;
      EXPECT_EQ(event.progress().label(), 1);
      EXPECT_EQ(event.progress().label_name(), "Liver");
      EXPECT_EQ(event.progress().label_index(), 1u);
      EXPECT_EQ(event.progress().label_count(), 1u);
    }
  }
  EXPECT_GT(named, 0);
  EXPECT_EQ(started, finished);
  EXPECT_TRUE(started.count("repair"));
  EXPECT_TRUE(started.count("marching_cubes"));
}

// With overlapping segments kept apart, the SEG refused above is meshed:
// each segment on its own.
TEST_F(MeshingServiceTest, OverlappingSegmentsCanBeMeshedEachOnItsOwn) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  ServiceHarness service(config_);
  v1::MeshOptions options = repaired_options();
  options.set_overlapping_segments(v1::OVERLAPPING_SEGMENTS_SEPARATE);
  // Its segments are small (64 and 16 voxels): keep every component.
  options.set_min_component_voxels(1);
  v1::SubmitReply reply;
  ASSERT_TRUE(service
                  .submit(shared_data("dicom-seg/highdicom-seg_image_ct_binary_overlap.dcm"),
                          options, &reply)
                  .ok());
  service.watch(reply.job_id());
  const v1::Job job = service.get(reply.job_id());
  ASSERT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED) << job.error().message();
  EXPECT_EQ(job.report().input().layers(), 2u);
  EXPECT_EQ(job.report().options().overlapping_segments(), v1::OVERLAPPING_SEGMENTS_SEPARATE);
  std::set<int32_t> outputs;
  for (const auto& surface : job.report().surfaces())
    if (surface.output()) outputs.insert(surface.label());
  EXPECT_EQ(outputs, (std::set<int32_t>{1, 2}));
}

TEST_F(MeshingServiceTest, CancelStopsARunningJobWithinASecond) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  ServiceHarness service(config_);
  v1::SubmitReply reply;
  ASSERT_THAT(service.submit(shared_data("liver.inr.gz"), liver_options(), &reply),
              testing::IsOk());
  // Follow the job until a stage after reading starts, then cancel.
  auto ctx = service.context();
  v1::WatchRequest watch;
  watch.set_job_id(reply.job_id());
  auto reader = service.stub().Watch(ctx.get(), watch);
  v1::JobEvent event;
  Clock::time_point cancelled_at{};
  std::vector<v1::JobEvent> events;
  while (reader->Read(&event)) {
    events.push_back(event);
    if (event.has_stage_started() && event.stage_started().stage() == "repair" &&
        cancelled_at == Clock::time_point{}) {
      auto cancel_ctx = service.context();
      v1::CancelRequest cancel;
      cancel.set_job_id(reply.job_id());
      v1::Job job;
      ASSERT_THAT(service.stub().Cancel(cancel_ctx.get(), cancel, &job), testing::IsOk());
      cancelled_at = Clock::now();
    }
  }
  ASSERT_THAT(reader->Finish(), testing::IsOk());
  ASSERT_NE(cancelled_at, Clock::time_point{}) << "no repair stage seen";
  EXPECT_TRUE(events.back().has_cancelled()) << events.back().DebugString();
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - cancelled_at).count(), 1.0);
  const v1::Job job = service.get(reply.job_id());
  EXPECT_EQ(job.state(), v1::JOB_STATE_CANCELLED);

  auto again_ctx = service.context();
  v1::CancelRequest cancel;
  cancel.set_job_id(reply.job_id());
  v1::Job ignored;
  EXPECT_EQ(service.stub().Cancel(again_ctx.get(), cancel, &ignored).error_code(),
            grpc::StatusCode::FAILED_PRECONDITION);
  auto fetch_ctx = service.context();
  v1::ListArtifactsRequest list;
  list.set_job_id(reply.job_id());
  v1::ListArtifactsReply artifacts;
  EXPECT_EQ(service.stub().ListArtifacts(fetch_ctx.get(), list, &artifacts).error_code(),
            grpc::StatusCode::FAILED_PRECONDITION);
}

TEST_F(MeshingServiceTest, JobOverTheDeadlineFailsWithDeadlineExceeded) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  config_.job_timeout = absl::Seconds(1);
  ServiceHarness service(config_);
  v1::SubmitReply reply;
  ASSERT_THAT(service.submit(shared_data("liver.inr.gz"), liver_options(), &reply),
              testing::IsOk());
  const auto events = service.watch(reply.job_id());
  ASSERT_TRUE(events.back().has_failed()) << events.back().DebugString();
  EXPECT_EQ(events.back().failed().code(), int(grpc::StatusCode::DEADLINE_EXCEEDED))
      << events.back().failed().message();
  const v1::Job job = service.get(reply.job_id());
  EXPECT_EQ(job.state(), v1::JOB_STATE_FAILED);
  EXPECT_LT(job.finished_at() - job.started_at(), 2.5);
}

// A strict job on a volume with labels too small to mesh fails with the
// reason; without strict the same job succeeds and its report lists them.
TEST_F(MeshingServiceTest, StrictJobWithALabelNotDeliveredFails) {
  ServiceHarness service(config_);
  const fs::path input = write_phantom(dir_, volume::PhantomShape::kThinShapes);
  v1::MeshOptions options = repaired_options();
  options.set_strict(true);
  v1::SubmitReply reply;
  ASSERT_THAT(service.submit(input, options, &reply), testing::IsOk());
  auto events = service.watch(reply.job_id());
  ASSERT_TRUE(events.back().has_failed()) << events.back().DebugString();
  EXPECT_EQ(events.back().failed().code(), int(grpc::StatusCode::FAILED_PRECONDITION));
  EXPECT_NE(events.back().failed().message().find("strict"), std::string::npos)
      << events.back().failed().message();

  options.set_strict(false);
  ASSERT_THAT(service.submit(input, options, &reply), testing::IsOk());
  events = service.watch(reply.job_id());
  ASSERT_TRUE(events.back().has_finished()) << events.back().DebugString();
  const auto& report = events.back().finished().report();
  ASSERT_GE(report.warnings_size(), 2);
  bool single_voxel_warned = false;
  for (const auto& warning : report.warnings())
    single_voxel_warned = single_voxel_warned || warning.label() == 9;
  EXPECT_TRUE(single_voxel_warned);
}

// A worker that sends its result and then lingers past the deadline (a
// scripted stand-in for one slow to exit): the result it sent stands.
TEST_F(MeshingServiceTest, AResultSentBeforeTheDeadlineStands) {
  const fs::path events = dir_ / "finished.events";
  {
    v1::JobEvent finished;
    finished.mutable_finished()->mutable_report()->set_labelmesh_version("scripted");
    const int fd = ::open(events.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    ASSERT_GE(fd, 0);
    ASSERT_TRUE(server::write_event(fd, finished));
    ::close(fd);
  }
  const fs::path lingering = dir_ / "lingering-worker.sh";
  // Called as `lingering-worker.sh --worker JOB_DIR OUT_DIR`.
  write_file(lingering,
             absl::StrCat("#!/bin/sh\n", kAnswersVersion, "echo '{}' >\"$3/report.json\"\n",
                          "cat '", events.string(), "' >&3\nexec sleep 30\n"));
  fs::permissions(lingering, fs::perms::owner_all);
  config_.worker_executable = lingering.string();
  config_.job_timeout = absl::Seconds(1);
  ServiceHarness service(config_);
  v1::SubmitReply reply;
  ASSERT_THAT(submit_sphere(service, &reply), testing::IsOk());
  const auto watched = service.watch(reply.job_id());
  ASSERT_TRUE(watched.back().has_finished()) << watched.back().DebugString();
  EXPECT_EQ(watched.back().finished().report().labelmesh_version(), "scripted");
  const v1::Job job = service.get(reply.job_id());
  EXPECT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED);
  // Stopped at the deadline, not left to sleep for 30 s.
  EXPECT_LT(job.finished_at() - job.started_at(), 2.5);
}

TEST_F(MeshingServiceTest, TwoWatchersSeeTheSameEvents) {
  config_.workers = 0;
  ServiceHarness service(config_);
  v1::SubmitReply reply;
  ASSERT_TRUE(
      service.submit(write_phantom(dir_, volume::PhantomShape::kTorus), repaired_options(), &reply)
          .ok());
  std::vector<v1::JobEvent> first, second;
  std::thread a([&] { first = service.watch(reply.job_id()); });
  std::thread b([&] { second = service.watch(reply.job_id()); });
  // Both watchers are attached to a queued job; cancelling ends both streams.
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  auto ctx = service.context();
  v1::CancelRequest cancel;
  cancel.set_job_id(reply.job_id());
  v1::Job job;
  ASSERT_THAT(service.stub().Cancel(ctx.get(), cancel, &job), testing::IsOk());
  EXPECT_EQ(job.state(), v1::JOB_STATE_CANCELLED);
  a.join();
  b.join();
  ASSERT_EQ(first.size(), 2u);
  ASSERT_EQ(second.size(), 2u);
  for (size_t i = 0; i < first.size(); ++i) {
    EXPECT_EQ(first[i].SerializeAsString(), second[i].SerializeAsString());
  }
  EXPECT_TRUE(first.back().has_cancelled());
  // A late watcher replays the same history.
  EXPECT_EQ(service.watch(reply.job_id()).size(), 2u);
}

TEST_F(MeshingServiceTest, QueuedJobRunsAfterARestart) {
  std::string job_id;
  {
    config_.workers = 0;
    ServiceHarness service(config_);
    v1::SubmitReply reply;
    ASSERT_THAT(submit_sphere(service, &reply), testing::IsOk());
    job_id = reply.job_id();
    service.shutdown();
  }
  // The record holds the options once, with every default filled in: the
  // job's, which GetJob shows and the worker reads.
  auto spool = server::Spool::open(spool_.string());
  ASSERT_THAT(spool, testing::IsOk());
  const auto records = spool->load_all();
  ASSERT_EQ(records.size(), 1u);
  EXPECT_FALSE(records[0].spec().has_options());
  EXPECT_EQ(records[0].job().options().surface(), repaired_options().surface());
  EXPECT_EQ(records[0].job().options().min_angle_deg(), 30);
  config_.workers = 1;
  ServiceHarness restarted(config_);
  const auto events = restarted.watch(job_id);
  ASSERT_FALSE(events.empty());
  EXPECT_TRUE(events.back().has_finished()) << events.back().DebugString();
  const v1::Job job = restarted.get(job_id);
  EXPECT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED);
  EXPECT_EQ(job.attempts(), 1u);
  // Its results outlive another restart, and the replay is the final state.
  restarted.shutdown();
  ServiceHarness again(config_);
  const auto replay = again.watch(job_id);
  ASSERT_EQ(replay.size(), 1u);
  EXPECT_TRUE(replay.front().has_finished());
}

TEST_F(MeshingServiceTest, ExpiredResultsAreDeletedAtStart) {
  std::string job_id;
  config_.result_ttl = absl::Seconds(1);
  {
    ServiceHarness service(config_);
    v1::SubmitReply reply;
    ASSERT_THAT(submit_sphere(service, &reply), testing::IsOk());
    job_id = reply.job_id();
    EXPECT_TRUE(service.watch(job_id).back().has_finished());
    service.shutdown();
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(1200));
  ServiceHarness restarted(config_);
  grpc::Status status;
  restarted.get(job_id, &status);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(job_dirs(), 0u);
}

TEST_F(MeshingServiceTest, EndedJobsBeyondTheCapAreDeletedOldestFirst) {
  config_.workers = 0;
  config_.max_ended_jobs = 2;
  ServiceHarness service(config_);
  std::vector<std::string> jobs;
  for (int i = 0; i < 3; ++i) {
    v1::SubmitReply reply;
    ASSERT_THAT(submit_sphere(service, &reply), testing::IsOk());
    auto context = service.context();
    v1::CancelRequest cancel;
    cancel.set_job_id(reply.job_id());
    v1::Job job;
    ASSERT_THAT(service.stub().Cancel(context.get(), cancel, &job), testing::IsOk());
    jobs.push_back(reply.job_id());
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  // Housekeeping runs every two seconds.
  grpc::Status oldest;
  for (int tries = 0; tries < 100; ++tries) {
    service.get(jobs[0], &oldest);
    if (!oldest.ok()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_EQ(oldest.error_code(), grpc::StatusCode::NOT_FOUND);
  for (size_t i = 1; i < jobs.size(); ++i) {
    grpc::Status kept;
    EXPECT_EQ(service.get(jobs[i], &kept).state(), v1::JOB_STATE_CANCELLED);
    EXPECT_THAT(kept, testing::IsOk()) << jobs[i];
  }
  EXPECT_EQ(job_dirs(), 2u);
}

TEST_F(MeshingServiceTest, CallsWithoutTheTokenAreUnauthenticated) {
  const fs::path token_file = dir_ / "token";
  write_file(token_file, "s3cret-token-0123456789\n");
  config_.auth_token_file = token_file.string();
  ServiceHarness service(config_);
  v1::ListJobsReply jobs;
  {
    auto ctx = service.context();
    EXPECT_EQ(service.stub().ListJobs(ctx.get(), {}, &jobs).error_code(),
              grpc::StatusCode::UNAUTHENTICATED);
  }
  service.token = "s3cret-token-0123456788";
  {
    auto ctx = service.context();
    EXPECT_EQ(service.stub().ListJobs(ctx.get(), {}, &jobs).error_code(),
              grpc::StatusCode::UNAUTHENTICATED);
  }
  v1::SubmitReply reply;
  EXPECT_EQ(submit_sphere(service, &reply).error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_EQ(job_dirs(), 0u);
  service.token = "s3cret-token-0123456789";
  auto ctx = service.context();
  EXPECT_THAT(service.stub().ListJobs(ctx.get(), {}, &jobs), testing::IsOk());
}

TEST_F(MeshingServiceTest, UnknownJobsAndArtifactsAreNotFound) {
  ServiceHarness service(config_);
  grpc::Status status;
  service.get(std::string(32, '0'), &status);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);
  service.get("../../etc", &status);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);
  v1::SubmitReply reply;
  ASSERT_THAT(submit_sphere(service, &reply), testing::IsOk());
  ASSERT_TRUE(service.watch(reply.job_id()).back().has_finished());
  for (const std::string name : {"../job.pb", "job.pb", "/etc/passwd", "missing.stl"}) {
    auto ctx = service.context();
    v1::FetchRequest request;
    request.set_job_id(reply.job_id());
    request.set_artifact(name);
    auto reader = service.stub().Fetch(ctx.get(), request);
    v1::FetchChunk chunk;
    EXPECT_FALSE(reader->Read(&chunk)) << name;
    EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::NOT_FOUND) << name;
  }
}

TEST_F(MeshingServiceTest, RefusesToStartWithAWorkerOfAnotherVersion) {
  const fs::path other = dir_ / "other-version-worker.sh";
  write_file(other, "#!/bin/sh\necho 'labelmesh-worker 0.0.0-other'\n");
  fs::permissions(other, fs::perms::owner_all);
  config_.worker_executable = other.string();
  auto started = server::LabelmeshServer::start(config_);
  ASSERT_FALSE(started.ok());
  EXPECT_THAT(started, testing::StatusIs(absl::StatusCode::kFailedPrecondition));
  EXPECT_TRUE(absl::StrContains(started.status().message(), "0.0.0-other"))
      << started.status().message();

  config_.worker_executable = (dir_ / "no-such-worker").string();
  started = server::LabelmeshServer::start(config_);
  ASSERT_FALSE(started.ok());
  EXPECT_TRUE(absl::StrContains(started.status().message(), "cannot be run"))
      << started.status().message();
}

TEST_F(MeshingServiceTest, AWorkerThatHangsAtVersionIsKilled) {
  const fs::path hanging = dir_ / "hanging-worker.sh";
  write_file(hanging, "#!/bin/sh\nexec sleep 60\n");
  fs::permissions(hanging, fs::perms::owner_all);
  const auto before = std::chrono::steady_clock::now();
  const absl::Status status =
      server::check_worker_version(hanging.string(), std::chrono::milliseconds(300));
  const auto waited = std::chrono::steady_clock::now() - before;
  EXPECT_THAT(status, testing::StatusIs(absl::StatusCode::kFailedPrecondition));
  EXPECT_TRUE(absl::StrContains(status.message(), "did not answer --version")) << status.message();
  EXPECT_LT(waited, std::chrono::seconds(30));
}

TEST_F(MeshingServiceTest, CrashedWorkerFailsOnlyItsJob) {
  const fs::path crashing = dir_ / "crashing-worker.sh";
  write_file(crashing, absl::StrCat("#!/bin/sh\n", kAnswersVersion, "kill -SEGV $$\n"));
  fs::permissions(crashing, fs::perms::owner_all);
  config_.worker_executable = crashing.string();
  ServiceHarness service(config_);
  v1::SubmitReply reply;
  const fs::path input = write_phantom(dir_, volume::PhantomShape::kSphere);
  ASSERT_THAT(service.submit(input, repaired_options(), &reply), testing::IsOk());
  const auto events = service.watch(reply.job_id());
  ASSERT_TRUE(events.back().has_failed());
  EXPECT_EQ(events.back().failed().code(), int(grpc::StatusCode::INTERNAL));
  EXPECT_TRUE(absl::StrContains(events.back().failed().message(), "SIGSEGV"))
      << events.back().failed().message();
  // The server is still there and takes the next job.
  ASSERT_THAT(service.submit(input, repaired_options(), &reply), testing::IsOk());
  EXPECT_TRUE(service.watch(reply.job_id()).back().has_failed());
}

}  // namespace
}  // namespace labelmesh::testing
