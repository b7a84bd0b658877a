// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/volume/label_table.h"

#include <gtest/gtest.h>

#include <fstream>

#include "absl/strings/match.h"
#include "absl/time/clock.h"
#include "core/util/utf8.h"
#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh::volume {
namespace {

std::string write_table(const std::string& file, const std::string& text) {
  const auto path = testing::scratch_dir("label-tables") / file;
  std::ofstream(path) << text;
  return path.string();
}

TEST(LabelTable, ReadsAnItkSnapLabelFile) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  auto table = read_label_table(testing::shared_data("MRIcrop-seg.label"));
  ASSERT_THAT(table, testing::IsOk());
  // Twelve rows; label 0 ("Clear") is the background.
  ASSERT_EQ(table->size(), 11u);
  EXPECT_EQ((*table)[0].label, 1);
  EXPECT_EQ((*table)[0].name, "vent-lat");
  EXPECT_EQ((*table)[0].colour, (std::array<uint8_t, 3>{0, 30, 255}));
  EXPECT_EQ((*table)[3].name, "hippo-R");
}

TEST(LabelTable, ReadsAFreeSurferColourTable) {
  auto table = read_label_table(write_table("lut.txt",
                                            "#No. Label Name: R G B A\n"
                                            "0   Unknown                 0   0   0   0\n"
                                            "2   Left-Cerebral-White-Matter  245 245 245 0\n"
                                            "41  Right-Cerebral-White-Matter 0 225 0 0\n"));
  ASSERT_THAT(table, testing::IsOk());
  ASSERT_EQ(table->size(), 2u);
  EXPECT_EQ((*table)[1].label, 41);
  EXPECT_EQ((*table)[1].name, "Right-Cerebral-White-Matter");
  EXPECT_EQ((*table)[1].colour, (std::array<uint8_t, 3>{0, 225, 0}));
}

TEST(LabelTable, ReadsAJsonMapOfNamesOrObjects) {
  auto table = read_label_table(write_table(
      "names.json", R"({"5": "liver", "114": {"name": "spleen", "color": [157, 108, 162]}})"));
  ASSERT_THAT(table, testing::IsOk());
  ASSERT_EQ(table->size(), 2u);
  EXPECT_EQ((*table)[0].label, 5);
  EXPECT_EQ((*table)[0].name, "liver");
  EXPECT_FALSE((*table)[0].colour.has_value());
  EXPECT_EQ((*table)[1].name, "spleen");
  EXPECT_EQ((*table)[1].colour, (std::array<uint8_t, 3>{157, 108, 162}));
}

TEST(LabelTable, AHashInsideAQuotedNameIsNoComment) {
  auto table =
      read_label_table(write_table("hash.label", "# lesions\n1 255 0 0 1 1 1 \"Lesion #2\"\n"));
  ASSERT_THAT(table, testing::IsOk());
  ASSERT_EQ(table->size(), 1u);
  EXPECT_EQ((*table)[0].name, "Lesion #2");
}

// A Latin-1 file: the report's string fields take only UTF-8.
TEST(LabelTable, NamesThatAreNotUtf8AreMadeValid) {
  auto table = read_label_table(write_table("latin1.label", "1 1 2 3 1 1 1 \"Gl\xe4ndula\"\n"));
  ASSERT_THAT(table, testing::IsOk());
  ASSERT_EQ(table->size(), 1u);
  EXPECT_EQ((*table)[0].name, "Gl?ndula");
  EXPECT_EQ(valid_utf8("Gl\xc3\xa4ndula \xe2\x82\xac"), "Gl\xc3\xa4ndula \xe2\x82\xac");
  EXPECT_EQ(valid_utf8("\xc0\xaf \xed\xa0\x80 a\tb"), "?? ??? a?b");
}

TEST(LabelTable, ErrorsNameTheFileAndLine) {
  const struct {
    const char* text;
    const char* expected;
  } cases[] = {
      {"1 0 0 0 1 1 1 \"open\n", "line 1: a label name without its closing quote"},
      {"# ok\n1 0 0 300 1 1 1 \"x\"\n", "line 2: colour components"},
      {"1 a 1 2 3 0\n1 b 1 2 3 0\n", "line 2: label 1 is named twice"},
      {"x y 1 2 3\n", "line 1: does not start with a label number"},
      {"{\"five\": \"liver\"}", "a key is not a label number"},
      {"{\"5\": 7}", "label 5: must be a name"},
  };
  for (const auto& c : cases) {
    const std::string path = write_table("bad.txt", c.text);
    auto table = read_label_table(path);
    ASSERT_FALSE(table.ok()) << c.text;
    EXPECT_THAT(table, testing::StatusIs(absl::StatusCode::kInvalidArgument));
    EXPECT_TRUE(absl::StrContains(table.status().message(), path)) << table.status();
    EXPECT_TRUE(absl::StrContains(table.status().message(), c.expected)) << table.status();
  }
  EXPECT_EQ(read_label_table("/no/such/table.label").status().code(), absl::StatusCode::kNotFound);
}

TEST(LabelTable, DeeplyNestedJsonIsRefusedAtOnce) {
  const std::string deep = "{\"1\": " + std::string(32000, '[') + std::string(32000, ']') + "}";
  const auto path = write_table("deep.json", deep);
  const absl::Time start = absl::Now();
  const auto refused = read_label_table(path);
  EXPECT_LT(absl::Now() - start, absl::Seconds(1));
  ASSERT_FALSE(refused.ok());
  EXPECT_THAT(refused, testing::StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_TRUE(absl::StrContains(refused.status().message(), "deep.json")) << refused.status();
  EXPECT_TRUE(absl::StrContains(refused.status().message(), "nests deeper than 8"))
      << refused.status();
  // Brackets inside a name do not count; a colour nests three deep.
  const auto fine = read_label_table(write_table(
      "fine.json", R"({"5": {"name": "[[[[[[[[[[ liver {{{{{{{{{{", "color": [1, 2, 3]}})"));
  ASSERT_THAT(fine, testing::IsOk());
  ASSERT_EQ(fine->size(), 1u);
  EXPECT_EQ((*fine)[0].name, "[[[[[[[[[[ liver {{{{{{{{{{");
}

TEST(LabelTable, ATableNamesOverWhatTheVolumeSaid) {
  LabelDescriptions described{named_label(1, "Liver", {{221, 130, 101}})};
  apply_label_table({named_label(1, "liver (segment 1)"), named_label(3, "kidney")}, described);
  ASSERT_EQ(described.size(), 2u);
  EXPECT_EQ(described[0].name, "liver (segment 1)");
  EXPECT_EQ(described[0].colour, (std::array<uint8_t, 3>{221, 130, 101}));
  EXPECT_EQ(described[1].label, 3);
}

}  // namespace
}  // namespace labelmesh::volume
