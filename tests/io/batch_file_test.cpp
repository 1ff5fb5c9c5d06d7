// Batch rows and their file (io/batch_file.hpp), and the provenance of a result (io/provenance.hpp).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "ctid/core/error.hpp"
#include "ctid/io/batch_file.hpp"
#include "ctid/io/json.hpp"
#include "ctid/io/provenance.hpp"
#include "test_util.hpp"

using namespace ctid;
namespace fs = std::filesystem;

namespace {
std::string text_of(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}
template <class T>
T cell(const BatchRow& row, const std::string& column) {
  const BatchCell* c = batch_cell(row, column);
  EXPECT_NE(c, nullptr) << column;
  return c ? std::get<T>(*c) : T{};
}
// A fitted result: G = 2/(s + 1), a1 = 1 +- 0.01, b0 = 2 +- 0.02, fit 97.5 %.
Result<AnyModel> fitted() {
  Result<AnyModel> r;
  r.model = TransferFunction({2.0}, {1.0, 1.0});
  r.parameters.names = {"a1", "b0"};
  r.parameters.values = Eigen::Vector2d(1.0, 2.0);
  r.parameters.std = Eigen::Vector2d(0.01, 0.02);
  r.parameters.fixed = {false, false};
  r.fit.fit_percent = 97.5;
  r.summary.termination = Termination::Converged;
  r.summary.seconds = 0.25;
  return r;
}
}  // namespace

TEST(BatchFile, RowOfAFitAndOfAFailure) {
  const Result<AnyModel> r = fitted();
  const BatchRow row = batch_row("a.csv", "srivc", &r, "", 9.0);
  std::vector<std::string> names;
  for (const auto& [n, c] : row) names.push_back(n);
  std::vector<std::string> expected = batch_columns();
  for (const char* p : {"a1", "a1_std", "b0", "b0_std"}) expected.push_back(p);
  EXPECT_EQ(names, expected);
  EXPECT_EQ(cell<std::string>(row, "model"), "transfer_function");
  EXPECT_EQ(cell<std::string>(row, "orders"), "nb=1 nf=1");
  EXPECT_EQ(cell<double>(row, "fit_percent"), 97.5);
  EXPECT_EQ(cell<std::string>(row, "termination"), "converged");
  EXPECT_TRUE(cell<bool>(row, "usable"));
  EXPECT_EQ(cell<double>(row, "seconds"), 0.25);  // the fit's own time, not the caller's
  EXPECT_EQ(cell<std::string>(row, "error"), "");
  EXPECT_EQ(cell<double>(row, "b0_std"), 0.02);

  const BatchRow bad = batch_row("b.csv", "srivc", nullptr, "b.csv: line 3:\nnot a number", 0.5);
  EXPECT_EQ(bad.size(), batch_columns().size());
  EXPECT_EQ(cell<std::string>(bad, "error"), "b.csv: line 3: not a number");  // one line
  EXPECT_TRUE(std::isnan(cell<double>(bad, "fit_percent")));
  EXPECT_FALSE(cell<bool>(bad, "usable"));
  EXPECT_EQ(cell<double>(bad, "seconds"), 0.5);
}

TEST(BatchFile, CsvGrowsItsHeaderAndResumesWithTypedCells) {
  const std::string path = test::temp_path("batch_rows.csv");
  fs::remove(path);
  const Result<AnyModel> r = fitted();
  {
    BatchFile f(path, false);
    f.add(batch_row("x, \"quoted\".csv", "srivc", nullptr, "cannot read", 0.5));
    EXPECT_EQ(text_of(path), "id,method,model,orders,fit_percent,termination,usable,seconds,error\n"
                             "\"x, \"\"quoted\"\".csv\",srivc,,,nan,,False,0.5,cannot read\n");
    f.add(batch_row("a.csv", "srivc", &r, "", 0));  // new columns: the file is rewritten with the wider header
    EXPECT_EQ(f.usable(), 1u);
  }
  EXPECT_EQ(text_of(path), "id,method,model,orders,fit_percent,termination,usable,seconds,error,a1,a1_std,b0,b0_std\n"
                           "\"x, \"\"quoted\"\".csv\",srivc,,,nan,,False,0.5,cannot read,,,,\n"
                           "a.csv,srivc,transfer_function,nb=1 nf=1,97.5,converged,True,0.25,,1,0.01,2,0.02\n");
  BatchFile again(path, true);
  ASSERT_EQ(again.rows().size(), 2u);
  EXPECT_TRUE(again.contains("x, \"quoted\".csv"));
  EXPECT_TRUE(again.contains("a.csv"));
  EXPECT_EQ(cell<double>(again.rows()[1], "b0_std"), 0.02);
  EXPECT_TRUE(cell<bool>(again.rows()[1], "usable"));
  EXPECT_TRUE(std::isnan(cell<double>(again.rows()[0], "a1")));  // an empty cell reads back as no value
  EXPECT_EQ(again.usable(), 1u);
}

TEST(BatchFile, JsonLinesRoundTripAndRefusals) {
  const std::string path = test::temp_path("batch_rows.jsonl");
  fs::remove(path);
  const Result<AnyModel> r = fitted();
  {
    BatchFile f(path, false);
    BatchRow row = batch_row("m/1", "srivc", &r, "", 0);
    row.emplace_back("seed", std::int64_t{1001});
    f.add(row);
    f.add(batch_row("m/2", "srivc", nullptr, "failed", 0.125));
  }
  const std::string text = text_of(path);
  EXPECT_NE(text.find("{\"id\":\"m/1\",\"method\":\"srivc\",\"model\":\"transfer_function\""), std::string::npos);
  EXPECT_NE(text.find("\"seed\":1001}"), std::string::npos);
  EXPECT_NE(text.find("\"fit_percent\":null"), std::string::npos);  // NaN as null
  BatchFile again(path, true);
  ASSERT_EQ(again.rows().size(), 2u);
  EXPECT_EQ(cell<std::int64_t>(again.rows()[0], "seed"), 1001);
  EXPECT_EQ(cell<double>(again.rows()[0], "a1_std"), 0.01);
  EXPECT_TRUE(std::isnan(cell<double>(again.rows()[1], "fit_percent")));

  EXPECT_THROW(BatchFile(test::temp_path("rows.txt"), false), InvalidArgument);
  const std::string other = test::temp_path("not_rows.csv");
  std::ofstream(other) << "u,y\n1,2\n";
  EXPECT_THROW(BatchFile(other, true), FileError);  // the first column is not id
}

TEST(Provenance, HashRowsAndResultFile) {
  // FNV-1a 64-bit reference values (Fowler, Noll, Vo: the published test vectors for "" and "a").
  const std::string empty = test::temp_path("empty.bin"), a = test::temp_path("a.bin");
  std::ofstream(empty).close();
  std::ofstream(a) << "a";
  EXPECT_EQ(file_content_hash(empty), "fnv1a64:cbf29ce484222325");
  EXPECT_EQ(file_content_hash(a), "fnv1a64:af63dc4c8601ec8c");
  EXPECT_THROW(file_content_hash(test::temp_path("no_such_file")), FileError);

  Provenance p = make_provenance("ctid fit a.bin");
  EXPECT_EQ(p.version, version());
  p.add_data_file(a, 1);
  p.add_data_file(a, 1);  // once per file
  p.preprocessing = {"a.bin: all 1 rows; no detrending", "b: all 2 rows"};
  const auto rows = p.rows();
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].second, "a.bin: all 1 rows; no detrending | b: all 2 rows");
  EXPECT_EQ(rows[1].second, "ctid fit a.bin");
  EXPECT_EQ(rows[2].second, a + ": 1 rows, fnv1a64:af63dc4c8601ec8c");
  EXPECT_EQ(p.made_by().rfind("ctid " + std::string(version()), 0), 0u);

  const std::string json = result_to_json(fitted(), "srivc", 2, &p);
  EXPECT_NE(json.find("\"command_line\": \"ctid fit a.bin\""), std::string::npos);
  EXPECT_NE(json.find("\"content_hash\": \"fnv1a64:af63dc4c8601ec8c\""), std::string::npos);
  const ResultFile back = parse_result_file(json, "r.json");  // readers ignore the member
  EXPECT_EQ(back.method, "srivc");
}
