// SPDX-License-Identifier: AGPL-3.0-or-later
// A DICOM Encapsulated STL object as DCMTK reads it back: the source's
// identifiers carried over, the required empty attributes present, UTC said,
// and a label name outside ASCII written as UTF-8.
#include "core/dicom/encapsulated_stl.h"

#include <dcmtk/config/osconfig.h>  // first, as DCMTK requires
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <gtest/gtest.h>

#include <string>

#include "support/test_files.h"

namespace labelmesh {
namespace {

std::string text(DcmDataset& dataset, const DcmTagKey& tag) {
  OFString value;
  return dataset.findAndGetOFStringArray(tag, value).good() ? value.c_str() : "<missing>";
}

dicom::DicomSource latin1_source() {
  dicom::DicomSource source;
  source.attributes = {{0x00080005, "ISO_IR 100"},
                       {0x00100010, "M\xFCller^Anna"},  // Latin-1 u umlaut
                       {0x00100020, "P-42"},
                       {0x0020000D, "1.2.3.4"},
                       {0x00200052, "1.2.3.5"}};
  source.sop_class_uid = "1.2.840.10008.5.1.4.1.1.66.4";
  source.sop_instance_uid = "1.2.3.6";
  return source;
}

TEST(EncapsulatedStl, CarriesTheSourceAndWritesANonAsciiTitleAsUtf8) {
  const auto dir = testing::scratch_dir("encapsulated_stl");
  const std::string stl(84 + 50, '\0');  // one (empty) triangle
  const auto path = (dir / "surface.dcm").string();
  const auto series = dicom::new_surface_series();
  ASSERT_TRUE(dicom::write_encapsulated_stl(stl, path, latin1_source(), series, 3,
                                            "Leber rechts \xC3\xBC")  // UTF-8 u umlaut
                  .ok());

  DcmFileFormat file;
  ASSERT_TRUE(file.loadFile(path.c_str()).good());
  DcmDataset& d = *file.getDataset();
  EXPECT_EQ(text(d, DCM_SOPClassUID), "1.2.840.10008.5.1.4.1.1.104.3");
  EXPECT_EQ(text(d, DCM_StudyInstanceUID), "1.2.3.4");
  EXPECT_EQ(text(d, DCM_FrameOfReferenceUID), "1.2.3.5");
  EXPECT_EQ(text(d, DCM_SeriesInstanceUID), series.series_instance_uid);
  EXPECT_EQ(text(d, DCM_InstanceNumber), "3");
  EXPECT_EQ(text(d, DCM_TimezoneOffsetFromUTC), "+0000");
  EXPECT_TRUE(d.tagExists(DCM_ConceptNameCodeSequence));
  EXPECT_EQ(text(d, DCM_SpecificCharacterSet), "ISO_IR 192");
  EXPECT_EQ(text(d, DCM_PatientName), "M\xC3\xBCller^Anna");
  EXPECT_EQ(text(d, DCM_DocumentTitle), "Leber rechts \xC3\xBC");
  Uint32 length = 0;
  ASSERT_TRUE(d.findAndGetUint32(DCM_EncapsulatedDocumentLength, length).good());
  EXPECT_EQ(length, stl.size());
}

TEST(EncapsulatedStl, AnUnwritablePathIsAnErrorNamingIt) {
  const auto status =
      dicom::write_encapsulated_stl(std::string(84, '\0'), "/nonexistent/x.dcm", latin1_source(),
                                    dicom::new_surface_series(), 1, "Liver");
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find("/nonexistent/x.dcm"), std::string::npos) << status;
}

}  // namespace
}  // namespace labelmesh
