// SPDX-License-Identifier: AGPL-3.0-or-later
// The broken-file corpus: every header problem is an error that names the
// file and the field, and nothing is allocated from a field before it is checked.
#include "core/header/volume_header.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <functional>
#include <limits>

#include "support/gzip_file.h"
#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh::volume {
namespace {

using testing::Nifti1Bytes;

std::string zlib_compress(std::string_view bytes) {
  uLongf size = compressBound(static_cast<uLong>(bytes.size()));
  std::string out(size, '\0');
  compress(reinterpret_cast<Bytef*>(out.data()), &size,
           reinterpret_cast<const Bytef*>(bytes.data()), static_cast<uLong>(bytes.size()));
  out.resize(size);
  return out;
}

std::string metaimage(std::string_view fields, std::string_view data_file = "LOCAL") {
  return std::string("ObjectType = Image\nNDims = 3\n") + std::string(fields) +
         "ElementDataFile = " + std::string(data_file) + "\n";
}

std::string nifti_with(const std::function<void(Nifti1Bytes&)>& change) {
  Nifti1Bytes n(4, 4, 4);
  change(n);
  return n.bytes();
}

std::string nifti2_with_dim0(int64_t dim0) {
  std::string h(544 + 8, '\0');
  const int32_t size = 540;
  std::memcpy(h.data(), &size, 4);
  std::memcpy(h.data() + 4, "n+2\0\r\n\032\n", 8);
  const int16_t datatype = 2, bitpix = 8;
  std::memcpy(h.data() + 12, &datatype, 2);
  std::memcpy(h.data() + 14, &bitpix, 2);
  std::memcpy(h.data() + 16, &dim0, 8);
  for (int i = 1; i < 8; ++i) {
    const int64_t one = i <= 3 ? 2 : 1;
    std::memcpy(h.data() + 16 + 8 * i, &one, 8);
  }
  for (int i = 0; i < 8; ++i) {
    const double one = 1.0;
    std::memcpy(h.data() + 104 + 8 * i, &one, 8);
  }
  const int64_t offset = 544;
  std::memcpy(h.data() + 168, &offset, 8);
  return h;
}

struct BrokenFile {
  std::string name;       // test name and file name
  std::string file;       // file name written in the scratch directory
  std::string bytes;      // its content
  bool gzip = false;      // gzip the content
  absl::StatusCode code;  // expected error
  std::string field;      // must appear in the message
};

std::vector<BrokenFile> corpus() {
  const auto bad = absl::StatusCode::kInvalidArgument;
  std::vector<BrokenFile> files = {
      {"TruncatedNiftiHeader", "short.nii", Nifti1Bytes(4, 4, 4).bytes().substr(0, 100), false, bad,
       "header"},
      {"BadSizeofHdr", "size.nii", nifti_with([](auto& n) { n.template put<int32_t>(0, 1234); }),
       false, bad, "sizeof_hdr"},
      {"BadMagic", "magic.nii",
       nifti_with([](auto& n) { std::memcpy(n.header.data() + 344, "abc\0", 4); }), false, bad,
       "magic"},
      {"TwoFileNifti", "pair.nii",
       nifti_with([](auto& n) { std::memcpy(n.header.data() + 344, "ni1\0", 4); }), false, bad,
       "magic"},
      {"RankZero", "rank0.nii", nifti_with([](auto& n) { n.template put<int16_t>(40, 0); }), false,
       bad, "dim[0]"},
      {"RankEight", "rank8.nii", nifti_with([](auto& n) { n.template put<int16_t>(40, 8); }), false,
       bad, "dim[0]"},
      {"Nifti2HugeRank", "rank.nii", nifti2_with_dim0(9000), false, bad, "dim[0]"},
      {"ZeroDimension", "dim0.nii", nifti_with([](auto& n) { n.template put<int16_t>(44, 0); }),
       false, bad, "dim[2]"},
      {"NegativeDimension", "dimneg.nii",
       nifti_with([](auto& n) { n.template put<int16_t>(46, -5); }), false, bad, "dim[3]"},
      {"TimeSeries", "4d.nii", nifti_with([](auto& n) {
         n.template put<int16_t>(40, 4);
         n.template put<int16_t>(48, 5);
       }),
       false, bad, "dim[4]"},
      {"SeventeenGigavoxels", "huge.nii", nifti_with([](auto& n) {
         n.template put<int16_t>(42, 32000);
         n.template put<int16_t>(44, 32000);
         n.template put<int16_t>(46, 17000);
       }),
       false, bad, "exceeds the limit"},
      {"ComplexVoxels", "complex.nii", nifti_with([](auto& n) {
         n.template put<int16_t>(70, 32);
         n.template put<int16_t>(72, 64);
       }),
       false, bad, "datatype"},
      {"BitpixMismatch", "bitpix.nii", nifti_with([](auto& n) { n.template put<int16_t>(72, 16); }),
       false, bad, "bitpix"},
      {"NanSpacing", "nan.nii", nifti_with([](auto& n) {
         n.template put<int16_t>(254, 0);
         n.template put<float>(80, std::numeric_limits<float>::quiet_NaN());
       }),
       false, bad, "pixdim"},
      {"NegativeSpacing", "neg.nii", nifti_with([](auto& n) {
         n.template put<int16_t>(254, 0);
         n.template put<float>(84, -1.0f);
       }),
       false, bad, "pixdim"},
      {"SingularSform", "singular.nii", nifti_with([](auto& n) {
         for (int i = 0; i < 12; ++i) n.template put<float>(280 + 4 * i, 0.0f);
       }),
       false, bad, "srow"},
      {"InfiniteSform", "inf.nii", nifti_with([](auto& n) {
         n.template put<float>(292, std::numeric_limits<float>::infinity());
       }),
       false, bad, "srow"},
      {"VoxOffsetInsideHeader", "offset.nii",
       nifti_with([](auto& n) { n.template put<float>(108, 100.0f); }), false, bad, "vox_offset"},
      {"TruncatedVoxels", "cut.nii", Nifti1Bytes(4, 4, 4).bytes().substr(0, 352 + 30), false, bad,
       "voxel data"},
      {"TruncatedGzipVoxels", "cut.nii.gz", Nifti1Bytes(8, 8, 8).bytes().substr(0, 352 + 100), true,
       bad, "voxel data"},
      {"MetaImageHugeDims", "huge.mha",
       metaimage("DimSize = 100000 100000 100000\nElementType = MET_UCHAR\n"), false, bad,
       "DimSize"},
      {"MetaImageNoDataFile", "nodata.mha", "ObjectType = Image\nNDims = 3\nDimSize = 2 2 2\n",
       false, bad, "header"},
      {"MetaImageEscapingDataFile", "escape.mhd",
       metaimage("DimSize = 2 2 2\nElementType = MET_UCHAR\n", "../../etc/passwd"), false, bad,
       "ElementDataFile"},
      {"MetaImageStringType", "string.mha",
       metaimage("DimSize = 2 2 2\nElementType = MET_STRING\n"), false, bad, "ElementType"},
      {"MetaImageVectorVoxels", "rgb.mha",
       metaimage("DimSize = 2 2 2\nElementType = MET_UCHAR\nElementNumberOfChannels = 3\n"), false,
       bad, "ElementNumberOfChannels"},
      {"MetaImageOversizedCompressedSize", "csize.mha",
       metaimage("DimSize = 2 2 2\nElementType = MET_UCHAR\nCompressedData = True\n"
                 "CompressedDataSize = 17000000000\n") +
           zlib_compress(std::string(8, '\1')),
       false, bad, "CompressedDataSize"},
      {"MetaImageCorruptZlib", "corrupt.mha",
       metaimage("DimSize = 64 64 64\nElementType = MET_UCHAR\nCompressedData = True\n") +
           std::string(64, '\x55'),
       false, bad, "voxel data"},
      {"MetaImageTextNumbers", "text.mha",
       metaimage("DimSize = two 2 2\nElementType = MET_UCHAR\n"), false, bad, "DimSize"},
      {"NrrdFourDimensions", "four.nrrd", "NRRD0004\ntype: uint8\ndimension: 4\nsizes: 2 2 2 2\n\n",
       false, bad, "dimension"},
      {"NrrdBzip2", "bz.nrrd",
       "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: bzip2\n\n" +
           std::string(8, '\0'),
       false, bad, "encoding"},
      {"NrrdNoEndian", "endian.nrrd",
       "NRRD0004\ntype: short\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n" +
           std::string(16, '\0'),
       false, bad, "endian"},
      {"NrrdMissingDirection", "dir.nrrd",
       "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nspace: LPS\n"
       "space directions: (1,0,0) none (0,0,1)\nencoding: raw\n\n" +
           std::string(8, '\0'),
       false, bad, "space directions"},
      {"InrNoEnd", "noend.inr", "#INRIMAGE-4#{\nXDIM=2\nYDIM=2\nZDIM=2\n" + std::string(300, '\n'),
       false, bad, "header"},
      {"InrOddPixsize", "pix.inr",
       [] {
         std::string h =
             "#INRIMAGE-4#{\nXDIM=2\nYDIM=2\nZDIM=2\nVDIM=1\nTYPE=unsigned fixed\nPIXSIZE=12 "
             "bits\n";
         h.append(252 - h.size(), '\n');
         return h + "##}\n" + std::string(16, '\0');
       }(),
       false, bad, "PIXSIZE"},
      {"VtiInvertedExtent", "extent.vti",
       "<VTKFile type=\"ImageData\"><ImageData WholeExtent=\"0 9 5 0 0 3\" Spacing=\"1 1 1\">"
       "<PointData><DataArray type=\"UInt8\"/></PointData></ImageData></VTKFile>",
       false, bad, "WholeExtent"},
      {"VtiVectorVoxels", "vector.vti",
       "<VTKFile type=\"ImageData\"><ImageData WholeExtent=\"0 1 0 1 0 1\" Spacing=\"1 1 1\">"
       "<PointData><DataArray type=\"UInt8\" "
       "NumberOfComponents=\"3\"/></PointData></ImageData></VTKFile>",
       false, bad, "NumberOfComponents"},
      {"VtiOriginOverflows", "far.vti",
       "<VTKFile type=\"ImageData\"><ImageData WholeExtent=\"-1e12 -1e12 0 0 0 0\" "
       "Spacing=\"1e300 1 1\"><PointData><DataArray type=\"UInt8\"/></PointData></ImageData>"
       "</VTKFile>",
       false, bad, "Origin"},
      {"UnknownExtension", "volume.ima", "DICM", false, bad, "extension"},
      {"DicomWithoutPreamble", "volume.dcm", "DICM", false, bad, "not a DICOM Part-10 file"},
  };
  return files;
}

class BrokenFileTest : public ::testing::TestWithParam<BrokenFile> {};

TEST_P(BrokenFileTest, IsRefusedWithTheFileAndFieldNamed) {
  const BrokenFile& broken = GetParam();
  const auto dir = testing::scratch_dir("broken-" + broken.name);
  const auto path = (dir / broken.file).string();
  if (broken.gzip) {
    ASSERT_TRUE(testing::write_gzip(path, broken.bytes));
  } else {
    testing::write_file(path, broken.bytes);
  }
  const auto header = check_volume_header(path);
  ASSERT_FALSE(header.ok()) << broken.name << " was accepted";
  EXPECT_EQ(header.status().code(), broken.code) << header.status();
  const std::string message(header.status().message());
  EXPECT_NE(message.find(path), std::string::npos) << message;
  EXPECT_NE(message.find(broken.field), std::string::npos) << message;
}

INSTANTIATE_TEST_SUITE_P(Corpus, BrokenFileTest, ::testing::ValuesIn(corpus()),
                         [](const auto& info) { return info.param.name; });

TEST(VolumeHeader, CorpusHasAtLeastTwentyFiles) { EXPECT_GE(corpus().size(), 20u); }

TEST(VolumeHeader, MissingFileIsNotFound) {
  const auto header = check_volume_header("/nonexistent/volume.nii.gz");
  ASSERT_FALSE(header.ok());
  EXPECT_THAT(header, testing::StatusIs(absl::StatusCode::kNotFound));
}

TEST(VolumeHeader, FreeTextHeaderFieldsAreNeverEchoed) {
  const auto dir = testing::scratch_dir("free-text");
  const auto path = (dir / "patient.mha").string();
  testing::write_file(path,
                      "ObjectType = Image\nNDims = 3\nJOHN DOE 1970-01-01\nDimSize = 2 2 2\n");
  const auto header = check_volume_header(path);
  ASSERT_FALSE(header.ok());
  EXPECT_EQ(std::string(header.status().message()).find("JOHN"), std::string::npos);
}

TEST(VolumeHeader, VoxelLimitIsConfigurable) {
  const auto dir = testing::scratch_dir("limit");
  const auto path = (dir / "small.nii").string();
  testing::write_file(path, Nifti1Bytes(10, 10, 10).bytes());
  EXPECT_THAT(check_volume_header(path), testing::IsOk());
  ReadLimits limits;
  limits.max_voxels = 999;
  const auto refused = check_volume_header(path, limits);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(std::string(refused.status().message()).find("limit of 999"), std::string::npos);
}

TEST(VolumeHeader, GzipBombIsBoundedByTheDeclaredSize) {
  // 8 declared voxels followed by 64 MiB of zeros that compress to ~64 KiB:
  // accepted, and the check inflates no more than the header needs.
  const auto dir = testing::scratch_dir("bomb");
  const auto path = (dir / "bomb.nii.gz").string();
  std::string bytes = Nifti1Bytes(2, 2, 2).bytes();
  bytes.append(size_t{64} << 20, '\0');
  ASSERT_TRUE(testing::write_gzip(path, bytes));
  const auto header = check_volume_header(path);
  ASSERT_THAT(header, testing::IsOk());
  EXPECT_EQ(header->data_bytes(), 8u);
}

// A gzip file whose size trailer claims enough data passes the header check
// without a full inflate; check_whole_payload decodes it all and finds the
// damage: a wrong CRC, and a stream cut at 60 % under a forged trailer.
TEST(VolumeHeader, WholePayloadCheckFindsWhatTheSizeTrailerHides) {
  const auto dir = testing::scratch_dir("whole-payload");
  Nifti1Bytes nifti(40, 40, 40);
  // Voxels that do not compress to nothing, so a cut lands among them.
  for (size_t i = 0; i < nifti.voxels.size(); ++i) nifti.voxels[i] = uint8_t((i * 7919) % 251);
  const std::string bytes = nifti.bytes();
  const auto good = (dir / "good.nii.gz").string();
  ASSERT_TRUE(testing::write_gzip(good, bytes));
  auto header = check_volume_header(good);
  ASSERT_THAT(header, testing::IsOk());
  EXPECT_THAT(check_whole_payload(*header), testing::IsOk());

  const std::string compressed = testing::read_bytes(good);
  ASSERT_GT(compressed.size(), 100u);
  std::string wrong_crc = compressed;
  wrong_crc[wrong_crc.size() - 8] ^= 0x5a;  // CRC32 comes before ISIZE
  const auto crc_path = (dir / "wrong-crc.nii.gz").string();
  testing::write_file(crc_path, wrong_crc);
  std::string cut = compressed.substr(0, compressed.size() * 6 / 10);
  cut += compressed.substr(compressed.size() - 4);  // the original ISIZE
  const auto cut_path = (dir / "cut.nii.gz").string();
  testing::write_file(cut_path, cut);
  for (const auto& path : {crc_path, cut_path}) {
    SCOPED_TRACE(path);
    auto damaged = check_volume_header(path);
    ASSERT_THAT(damaged, testing::IsOk()) << "the header check alone was expected to pass";
    const absl::Status whole = check_whole_payload(*damaged);
    EXPECT_THAT(whole, testing::StatusIs(absl::StatusCode::kInvalidArgument));
    EXPECT_NE(std::string(whole.message()).find(path), std::string::npos) << whole.message();
  }
}

}  // namespace
}  // namespace labelmesh::volume
