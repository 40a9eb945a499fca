// The dataset manifest reader (datalog/dataset_manifest.h): a manifest as the
// plant writes it reads back; every malformed one is a LogError naming the
// manifest and the field (issue 19, finding 4: wrong types aborted
// `hadynet validate` with an uncaught JSON exception).
#include "datalog/dataset_manifest.h"

#include <gtest/gtest.h>

#include <string>

namespace hadynet::datalog {
namespace {

TEST(DatasetManifest, ReadsWhatThePlantWrites) {
  const DatasetManifest m = parse_dataset_manifest(R"({
    "format": "hadynet-dataset", "format_version": 1, "preset": "paper", "seed": 1, "dt_s": 0.2,
    "logs": [{"file": "train/a.csv", "split": "train", "state": "Ball/i0/w0", "rows": 300},
             {"file": "test/b.csv"}]})",
                                                   "m.json");
  ASSERT_EQ(m.logs.size(), 2u);
  EXPECT_EQ(m.logs[0].file, "train/a.csv");
  EXPECT_EQ(m.logs[0].split, "train");
  EXPECT_EQ(m.logs[0].rows, std::optional<std::size_t>(300));
  EXPECT_EQ(m.logs[1].split, "?");
  EXPECT_FALSE(m.logs[1].rows.has_value());
}

struct BadManifest {
  const char* name;
  const char* text;
  const char* message;  // the whole message after "m.json: "
};

class DatasetManifestRejects : public ::testing::TestWithParam<BadManifest> {};

TEST_P(DatasetManifestRejects, NamingTheField) {
  const BadManifest& c = GetParam();
  try {
    parse_dataset_manifest(c.text, "m.json");
    FAIL() << "accepted " << c.text;
  } catch (const LogError& e) {
    EXPECT_EQ(std::string(e.what()), std::string("m.json: ") + c.message);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Manifests, DatasetManifestRejects,
    ::testing::Values(
        BadManifest{"SplitNumber", R"({"format":"hadynet-dataset","logs":[{"file":"a.csv","split":5}]})",
                    "field 'logs[0].split': expected a string, got a whole number"},
        BadManifest{"FormatNumber", R"({"format":7,"logs":[]})",
                    "field 'format': expected a string, got a whole number"},
        BadManifest{"RowsBeyondDouble", R"({"format":"hadynet-dataset","logs":[{"file":"a.csv","rows":1e400}]})",
                    "not readable JSON: a number beyond the range of a double"},
        BadManifest{"RowsNegative", R"({"format":"hadynet-dataset","logs":[{"file":"a.csv","rows":-3}]})",
                    "field 'logs[0].rows': expected a whole number >= 0, got -3"},
        BadManifest{"RowsFraction", R"({"format":"hadynet-dataset","logs":[{"file":"a.csv","rows":2.5}]})",
                    "field 'logs[0].rows': expected a whole number >= 0, got a number with a fraction or exponent"},
        BadManifest{"FileOutside", R"({"format":"hadynet-dataset","logs":[{"file":"../../etc/x.csv"}]})",
                    "field 'logs[0].file': the path '../../etc/x.csv' leaves the dataset folder ('..')"},
        BadManifest{"FileAbsolute", R"({"format":"hadynet-dataset","logs":[{"file":"/x.csv"}]})",
                    "field 'logs[0].file': expected a path relative to the dataset folder, got '/x.csv'"},
        BadManifest{"LogsNotArray", R"({"format":"hadynet-dataset","logs":{}})",
                    "field 'logs': expected an array, got an object"},
        BadManifest{"NotJson", R"({"format":)", "byte 11: not valid JSON"},
        BadManifest{"WrongFormat", R"({"format":"other","logs":[]})",
                    "field 'format': expected \"hadynet-dataset\", got 'other'"},
        BadManifest{"WrongVersion", R"({"format":"hadynet-dataset","format_version":2,"logs":[]})",
                    "field 'format_version': expected 1, got 2"}),
    [](const auto& param_info) { return std::string(param_info.param.name); });

}  // namespace
}  // namespace hadynet::datalog
