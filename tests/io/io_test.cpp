#include <cmath>
#include <complex>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>

#include <gtest/gtest.h>

#include "ctid/core/error.hpp"
#include "ctid/io/csv.hpp"
#include "ctid/io/json.hpp"
#include "ctid/io/load.hpp"
#include "ctid/io/mat.hpp"
#include "test_util.hpp"

using namespace ctid;
using test::error_of;
namespace fs = std::filesystem;

namespace {
std::string write_text(const std::string& name, const std::string& text) {
  const std::string p = test::temp_path(name);
  std::ofstream(p) << text;
  return p;
}
}  // namespace

TEST(Csv, DelimitersHeadersComments) {
  const CsvTable a = parse_csv("# a comment\nt,u,y\n0,1,2\n0.1,3,4\n", "a.csv");
  EXPECT_EQ(a.names, (std::vector<std::string>{"t", "u", "y"}));
  EXPECT_EQ(a.values(1, 2), 4.0);
  EXPECT_EQ(a.line_numbers[1], 4);
  const CsvTable b = parse_csv("u;y\n1;2\n", "b.csv");
  EXPECT_EQ(b.values(0, 1), 2.0);
  // DaISy style: no header, tab separated, trailing tab, CRLF.
  const CsvTable c = parse_csv("   6.41e+00\t4.76e+00\t\r\n   3.41e+00\t4.77e+00\t\r\n", "c.dat");
  EXPECT_EQ(c.names, (std::vector<std::string>{"1", "2"}));
  EXPECT_EQ(c.values(1, 0), 3.41);
  EXPECT_EQ(c.column("2"), 1);
  EXPECT_EQ(a.column("y"), 2);
  EXPECT_NE(error_of([&] { a.column("z"); }).find("no column named 'z' (columns: t, u, y)"), std::string::npos);
}

TEST(Csv, ErrorsNameFileLineAndColumn) {
  EXPECT_EQ(error_of([] { parse_csv("u,y\n1,2\n3\n", "f.csv"); }), "f.csv:3: expected 2 fields, found 1");
  EXPECT_EQ(error_of([] { parse_csv("u,y\n1,abc\n", "f.csv"); }),
            "f.csv:2: column 'y' (field 2): cannot read 'abc' as a number");
  EXPECT_EQ(error_of([] { parse_csv("u,y\n1,nan\n", "f.csv"); }), "f.csv:2: column 'y' (field 2): value 'nan' is not finite");
  EXPECT_EQ(error_of([] { parse_csv("u,y\n", "f.csv"); }), "f.csv: no data rows");
  EXPECT_THROW(read_csv("/nonexistent/x.csv"), FileError);
}

TEST(Csv, WriteReadRoundTripIsExact) {
  Eigen::MatrixXd m(3, 2);
  m << 0.1, -1e-300, 1.0 / 3.0, 123456789.123456789, -2.5, 6.02214076e23;
  const std::string p = test::temp_path("rt.csv");
  write_csv(p, {"a", "b"}, m);
  const CsvTable t = read_csv(p);
  EXPECT_EQ(t.values, m);
  // A failed write leaves nothing behind.
  EXPECT_THROW(write_csv("/nonexistent_dir/x.csv", {"a", "b"}, m), FileError);
}

TEST(Load, TimeColumnUniformIrregularAndNonIncreasing) {
  const std::string uni = write_text("uni.csv", "t,u,y\n0,1,2\n0.1,3,4\n0.2,5,6\n");
  DataSpec s;
  s.inputs = {"u"};
  s.outputs = {"y"};
  s.time = "t";
  const IdData d = load_iddata(uni, s);
  EXPECT_TRUE(d.is_uniform());
  EXPECT_NEAR(d.ts(), 0.1, 1e-15);
  EXPECT_EQ(d.output_names()[0], "y");
  const IdData irr = load_iddata(write_text("irr.csv", "t,u,y\n0,1,2\n0.1,3,4\n0.35,5,6\n"), s);
  EXPECT_FALSE(irr.is_uniform());
  const std::string bad = write_text("bad.csv", "t,u,y\n0,1,2\n0.2,3,4\n0.1,5,6\n");
  const std::string msg = error_of([&] { load_iddata(bad, s); });
  EXPECT_NE(msg.find("bad.csv:4: time column 't' is not strictly increasing (0.1 after 0.2)"), std::string::npos) << msg;
  EXPECT_THROW(load_iddata(bad, s), FileError);
  s.time.clear();
  EXPECT_THROW(load_iddata(uni, s), InvalidArgument);  // neither time column nor Ts
  s.ts = 0.5;
  s.inputs = {"flow"};
  EXPECT_NE(error_of([&] { load_iddata(uni, s); }).find("no column named 'flow'"), std::string::npos);
}

// choose_record: the defaults ctid fit and ctid.load share. A column named Time is the time axis; the other columns
// are the inputs, the last the output; rows 2:4 keep rows 2..4; the means removed are those of the rows kept
// (u: (3 + 5 + 7)/3 = 5, y: (4 + 6 + 9)/3 = 19/3, printed with 6 digits); the choices the file cannot satisfy are
// ColumnSelectionError, bad rows InvalidOptions.
TEST(Load, ChooseRecordDefaultsRowsAndDetrending) {
  const std::string f = write_text("choose.csv", "Time,u,y\n0,1,2\n0.1,3,4\n0.2,5,6\n0.3,7,9\n");
  RecordChoice c;
  ChosenRecord r = choose_record(f, c);
  EXPECT_EQ(r.time_column, "Time");
  EXPECT_EQ(r.data.input_names(), (std::vector<std::string>{"u"}));
  EXPECT_EQ(r.data.output_names(), (std::vector<std::string>{"y"}));
  EXPECT_EQ(r.data.size(), 4);
  EXPECT_EQ(r.preprocessing, "all 4 rows; no detrending");
  c.rows = "2:4";
  c.detrend = Detrend::Mean;
  r = choose_record(f, c);
  EXPECT_EQ(r.data.size(), 3);
  EXPECT_EQ(r.first_row, 2);
  EXPECT_EQ(r.last_row, 4);
  EXPECT_NEAR(r.removed.u_offset(0), 5.0, 1e-15);
  EXPECT_NEAR(r.removed.y_offset(0), 19.0 / 3.0, 1e-14);
  EXPECT_NEAR(r.data.y().col(0).sum(), 0.0, 1e-13);
  EXPECT_EQ(r.preprocessing, "rows 2..4 of 4; means removed (input u 5, output y 6.33333)");
  c.rows = "0:3";
  EXPECT_THROW(choose_record(f, c), InvalidOptions);
  EXPECT_NE(error_of([&] { choose_record(f, c); }).find("rows 0:3: '0' is not a row number from 1 to 4"), std::string::npos);
  const std::string two = write_text("two_times.csv", "T,time,u,y\n0,0,1,2\n1,1,3,4\n");
  EXPECT_THROW(choose_record(two, {}), ColumnSelectionError);
  EXPECT_NE(error_of([&] { choose_record(two, {}); }).find("columns 'T' and 'time' could both be the time axis"),
            std::string::npos);
  RecordChoice wide;
  wide.ts = 0.1;
  EXPECT_THROW(choose_record(write_text("wide.csv", "a,b,c\n1,2,3\n4,5,6\n"), wide), ColumnSelectionError);
  wide.outputs = {"c"};  // an output given: every other column is an input
  EXPECT_EQ(choose_record(write_text("wide2.csv", "a,b,c\n1,2,3\n4,5,6\n"), wide).data.nu(), 2);
}

TEST(Load, FrequencyDataFromTheResponseOrTheSpectra) {
  // G(jw) = 1/(1 + jw) at w = 1, 2: from re/im directly, and as Y/U from spectra U = 2, Y = 2 G (exact in binary).
  const std::string f = write_text("freq.csv", "w,re,im,ur,ui,yr,yi\n1,0.5,-0.5,2,0,1,-1\n2,0.2,-0.4,2,0,0.4,-0.8\n");
  int rows = 0;
  const FrequencyData g = load_frequency_data(f, {}, &rows);
  EXPECT_EQ(rows, 2);
  EXPECT_EQ(g.response()(1), std::complex<double>(0.2, -0.4));
  FrequencyColumns spectra;
  spectra.u_re = "ur";
  spectra.u_im = "ui";
  spectra.y_re = "yr";
  spectra.y_im = "yi";
  EXPECT_NEAR(std::abs(load_frequency_data(f, spectra).response()(1) - std::complex<double>(0.2, -0.4)), 0.0, 1e-15);
  // The options' problems (a column the file lacks, spectra named in part) and the file's content are told apart.
  FrequencyColumns missing;
  missing.re = "real";
  EXPECT_THROW(load_frequency_data(f, missing), ColumnSelectionError);
  spectra.y_im.clear();
  EXPECT_THROW(load_frequency_data(f, spectra), InvalidOptions);
  const std::string bad = write_text("freq_bad.csv", "w,re,im\n2,1,0\n1,1,0\n");
  EXPECT_NE(error_of([&] { load_frequency_data(bad, {}); }).find(bad + ": "), std::string::npos);
}

TEST(Json, ModelAndResultRoundTrip) {
  const TransferFunction g(Eigen::VectorXd{{-6400.0, 1600.0}}, Eigen::VectorXd{{1.0, 5.0, 408.0, 416.0, 1600.0}}, 0.25);
  const LinearModel back = parse_model_json(model_to_json(g));
  const auto& tf = std::get<TransferFunction>(back);
  EXPECT_EQ(tf.num().coefficients(), g.num().coefficients());
  EXPECT_EQ(tf.den().coefficients(), g.den().coefficients());
  EXPECT_EQ(tf.io_delay(), 0.25);
  const StateSpace ss = g.to_state_space();
  const StateSpace ss2 = std::get<StateSpace>(parse_model_json(model_to_json(ss)));
  EXPECT_EQ(ss2.A(), ss.A());
  EXPECT_EQ(ss2.C(), ss.C());

  Result<TransferFunction> r;
  r.model = g;
  r.parameters.names = {"a1", "b0"};
  r.parameters.values = Eigen::VectorXd{{5.0, -6400.0}};
  r.parameters.std = Eigen::VectorXd{{0.1, NAN}};
  r.parameters.fixed = {false, true};
  r.parameters.covariance = Eigen::MatrixXd{{0.01, 0}, {0, 0}};
  r.fit = FitReport{93.2, 0.068, 1e-3, 1.1e-3, -100, -99, -95, 1000, 6};
  r.summary = Summary{Termination::Converged, "ok", 12, 0.004};
  r.diagnostics.condition_number = 12.5;
  r.diagnostics.warnings = {"w1"};
  r.diagnostics.set(diagnostic::tau, 0.5);
  r.diagnostics.set(diagnostic::theta_tau, Eigen::VectorXd{{1.0, 2.0}});
  const std::string text = result_to_json(r, "lssvf");
  const Result<TransferFunction> q = parse_result_json(text);
  EXPECT_EQ(q.parameters.names, r.parameters.names);
  EXPECT_EQ(q.parameters.values, r.parameters.values);
  EXPECT_TRUE(std::isnan(q.parameters.std(1)));
  EXPECT_EQ(q.parameters.fixed, r.parameters.fixed);
  EXPECT_EQ(q.fit.fit_percent, 93.2);
  EXPECT_EQ(q.fit.n_parameters, 6);
  EXPECT_EQ(q.summary.termination, Termination::Converged);
  EXPECT_EQ(q.summary.iterations, 12);
  EXPECT_EQ(q.diagnostics.get(diagnostic::tau), 0.5);
  EXPECT_EQ(q.diagnostics.get(diagnostic::theta_tau), r.diagnostics.get(diagnostic::theta_tau));
  EXPECT_EQ(q.diagnostics.warnings, r.diagnostics.warnings);
  EXPECT_NE(text.find("\"method\": \"lssvf\""), std::string::npos);
  // The envelope is accepted where a model is expected.
  EXPECT_EQ(std::get<TransferFunction>(parse_model_json(text)).io_delay(), 0.25);
  // Fuzz finding (tests/fuzz/corpus/json/regression-count-out-of-range.json): a count of 1.67e71 was converted to
  // int (undefined behaviour); counts must be whole numbers in [0, INT_MAX].
  auto with_samples = [&](const std::string& v) {
    std::string t = text;
    const std::string key = "\"n_samples\": 1000";
    t.replace(t.find(key), key.size(), "\"n_samples\": " + v);
    return t;
  };
  EXPECT_EQ(error_of([&] { parse_result_json(with_samples("1.66667e+71"), "r.json"); }),
            "r.json: \"fit.n_samples\" must be a whole number in [0, 2147483647], got 1.66667e+71");
  EXPECT_THROW(parse_result_json(with_samples("-3"), "r.json"), FileError);
  EXPECT_THROW(parse_result_json(with_samples("2.5"), "r.json"), FileError);
  EXPECT_THROW(parse_result_json(with_samples("\"many\""), "r.json"), FileError);
  EXPECT_EQ(parse_result_json(with_samples("1e3")).fit.n_samples, 1000);
}

TEST(Json, MalformedFilesAreFileErrors) {
  EXPECT_NE(error_of([] { parse_model_json("{", "m.json"); }).find("m.json: not valid JSON"), std::string::npos);
  EXPECT_EQ(error_of([] { parse_model_json("{\"type\": \"transfer_function\", \"den\": [1, 2]}", "m.json"); }),
            "m.json: the model has no member \"num\"");
  EXPECT_NE(error_of([] { parse_model_json("{\"type\": \"transfer_function\", \"num\": [1, 2, 3], \"den\": [1, 2]}", "m.json"); })
                .find("improper"),
            std::string::npos);
  EXPECT_NE(error_of([] { parse_model_json("{\"type\": \"narx\"}", "m.json"); }).find("\"narx\""), std::string::npos);
  EXPECT_THROW(read_model_json("/nonexistent.json"), FileError);
  // Fuzz finding (tests/fuzz/corpus/json/regression-io-delay-string.json): a non-numeric io_delay ended in
  // std::terminate (an uncaught json type_error).
  EXPECT_EQ(error_of([] {
              parse_model_json(R"({"type": "transfer_function", "num": [1], "den": [1, 2], "io_delay": "D^2y"})", "m.json");
            }),
            "m.json: \"io_delay\" must be a number (seconds)");
  // Fuzz finding (tests/fuzz/corpus/json/regression-number-overflow.json): a number beyond double range is a
  // json out_of_range exception, not a parse_error; it ended in std::terminate.
  EXPECT_NE(error_of([] { parse_model_json(R"({"type": "transfer_function", "num": [1e99999], "den": [1, 2]})", "m.json"); })
                .find("m.json: not valid JSON: [json.exception.out_of_range.406] number overflow"),
            std::string::npos);
  // A key twice in one object (before: the last value won silently, k = 50 instead of 2); the same key in two
  // objects is fine.
  const std::string twice = R"({"type": "greybox", "inputs": ["u"], "states": ["x"], "outputs": {"y": "x"},
      "parameters": {"k": 2, "k": 50}, "equations": {"x": "-k*x + u"}})";
  EXPECT_EQ(error_of([&] { parse_greybox_json(twice, "g.json"); }),
            "g.json: the key \"k\" appears twice in one object; a JSON reader would silently keep one of the values: "
            "keep the one you mean");
  EXPECT_EQ(parse_greybox_json(R"({"type": "greybox", "inputs": ["u"], "states": ["x"], "outputs": {"x": "x"},
      "parameters": {"k": 2}, "equations": {"x": "-k*x + u"}})").parameter_values()(0), 2.0);
}

TEST(Mat, WriteReadAndLoad) {
  const std::string p = test::temp_path("d.mat");
  Eigen::MatrixXd u = Eigen::VectorXd::LinSpaced(50, 0, 1), y = u.array().square();
  write_mat(p, {{"u", u}, {"y", y}, {"grid", Eigen::MatrixXd::Ones(2, 3)}});
  const auto names = mat_variable_names(p);
  EXPECT_EQ(names.size(), 3u);
  EXPECT_EQ(read_mat_variable(p, "y"), y);
  EXPECT_EQ(read_mat_variable(p, "grid").cols(), 3);
  DataSpec s;
  s.inputs = {"u"};
  s.outputs = {"y"};
  s.ts = 0.02;
  const IdData d = load_iddata(p, s);
  EXPECT_EQ(d.size(), 50);
  EXPECT_EQ(d.y()(49, 0), 1.0);
  EXPECT_NE(error_of([&] { read_mat_variable(p, "nope"); }).find("no variable named 'nope'"), std::string::npos);
  s.outputs = {"grid"};
  EXPECT_THROW(load_iddata(p, s), FileError);
  EXPECT_THROW(mat_variable_names("/nonexistent.mat"), FileError);
}

TEST(RealData, DaisyHairDryerReads) {
  const std::string path = std::string(CTID_EXAMPLES_DATA_DIR) + "/dryer.dat";
  if (!fs::exists(path)) GTEST_SKIP() << "bundled data not present";
  DataSpec s;
  s.inputs = {"1"};
  s.outputs = {"2"};
  s.ts = 0.08;
  const IdData d = load_iddata(path, s);
  // DaISy README: 1000 samples; means 5.0 V in, 4.89 out.
  EXPECT_EQ(d.size(), 1000);
  EXPECT_NEAR(d.u().mean(), 5.0, 0.05);
  EXPECT_NEAR(d.y().mean(), 4.89, 0.01);
}

TEST(Json, NarxAndNdeModelsRoundTripAndBadFilesAreNamed) {
  Result<NarxModel> r;
  r.model = NarxModel({NarxTerm::parse("y(k-1)"), NarxTerm::parse("y(k-1)*u(k-2)"), NarxTerm::parse("e(k-1)")},
                      Eigen::Vector3d(0.5, -0.25, 0.1), 0.01);
  r.parameters.names = {"y(k-1)", "y(k-1)*u(k-2)", "e(k-1)"};
  r.parameters.values = r.model.coefficients();
  const NarxModel back = parse_narx_json(result_to_json(r, "narx"));
  EXPECT_EQ(back.terms(), r.model.terms());
  EXPECT_EQ(back.coefficients(), r.model.coefficients());
  EXPECT_EQ(back.ts(), 0.01);
  // NDE: written normalised (y coefficient +1), read back.
  Result<NdeModel> n;
  n.model = NdeModel({NdeTerm::parse("y"), NdeTerm::parse("D^2y"), NdeTerm::parse("u"), NdeTerm::parse("y*Dy")},
                     Eigen::Vector4d(2.0, 2e-4, -2.0, -0.012));
  const NdeModel nb = parse_nde_json(result_to_json(n, "kia"));
  EXPECT_DOUBLE_EQ(nb.coefficient("y"), 1.0);
  EXPECT_DOUBLE_EQ(nb.coefficient("y*Dy"), -0.006);
  // Unknown term names and wrong types are reported with the file name and the position.
  try {
    parse_narx_json(R"J({"type": "narx", "ts": 1, "terms": [{"name": "y(k-1)*x(k-2)", "value": 1}]})J", "m.json");
    FAIL() << "no error";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("m.json: terms[0]"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("position 8"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse_nde_json(R"J({"type": "narx", "ts": 1, "terms": []})J"), FileError);
  EXPECT_THROW(parse_narx_json(R"J({"type": "narx", "terms": []})J"), FileError);  // no ts
}

TEST(Mat, DamagedFilesAreRefusedBeforeLibmatioAllocates) {
  // Found by tests/fuzz/mat_fuzz: libmatio allocates the sizes a file declares (7.5 GB for a 177-byte file). The
  // structure is now checked first: each of these gives a FileError naming the problem, quickly, with no allocation.
  std::string hdr = "MATLAB 5.0 MAT-file, Platform: GLNXA64, Created by: ctid test";
  hdr.resize(116, ' ');
  hdr += std::string(8, '\0') + std::string("\x00\x01", 2) + "IM";
  auto le32 = [](std::uint32_t v) { return std::string{char(v), char(v >> 8), char(v >> 16), char(v >> 24)}; };
  auto file = [&](const std::string& name, const std::string& body) {
    const std::string p = test::temp_path(name);
    std::ofstream(p, std::ios::binary) << hdr << body;
    return p;
  };
  const std::string flags = le32(6) + le32(8) + le32(6) + le32(0);  // miUINT32 flags: class double
  // 1. The top-level element declares more bytes than the file holds.
  const std::string cut = file("cut.mat", le32(14) + le32(112) + flags);
  EXPECT_NE(error_of([&] { mat_variable_names(cut); }).find("declares 112 bytes but only 16 remain"), std::string::npos);
  // 2. Inside an array, the dimensions part declares 3.7 GB.
  const std::string dims = le32(5) + le32(0xe0530008u) + le32(1) + le32(1);
  const std::string huge = file("huge.mat", le32(14) + le32(32) + flags + dims);
  EXPECT_NE(error_of([&] { mat_variable_names(huge); }).find("an array part declares 3763535880 bytes"), std::string::npos);
  // 3. Dimensions of 60 x 60 doubles with 8 bytes of data.
  const std::string big = le32(5) + le32(8) + le32(60) + le32(60);
  const std::string name = le32(1) + le32(1) + "x" + std::string(7, '\0');
  const std::string data = le32(9) + le32(8) + std::string(8, '\0');
  const std::string many = file("many.mat", le32(14) + le32(64) + flags + big + name + data);
  EXPECT_NE(error_of([&] { mat_variable_names(many); }).find("an array of 3600 elements"), std::string::npos);
  // 3b. 100000 x 0: no elements, but a dimension larger than the file (libmatio may allocate by it).
  const std::string wide = le32(5) + le32(8) + le32(100000) + le32(0);
  const std::string empty = file("empty.mat", le32(14) + le32(64) + flags + wide + name + data);
  EXPECT_NE(error_of([&] { mat_variable_names(empty); }).find("an array dimension of 100000"), std::string::npos);
  // 4. A compressed element that is not zlib data.
  const std::string z = file("z.mat", le32(15) + le32(8) + std::string("\x78\x9c\xff\xff\xff\xff\xff\xff", 8));
  EXPECT_NE(error_of([&] { mat_variable_names(z); }).find("compressed element"), std::string::npos);
  // 5. A version word that is neither level 5 (0x0100) nor 7.3 (0x0200): libmatio read it as level 5 unchecked
  //    (tests/fuzz/corpus/mat/regression-unknown-version.mat: 2 GB resident for a 164-byte file).
  std::string odd = hdr;
  odd[124] = '\x10';
  const std::string v = test::temp_path("version.mat");
  std::ofstream(v, std::ios::binary) << odd << le32(14) + le32(16) + flags;
  EXPECT_NE(error_of([&] { mat_variable_names(v); }).find("unknown version 0x0110"), std::string::npos);
  // 6. A sparse array (class 5) whose parts are damaged: only the header is read before the class is refused
  //    (tests/fuzz/corpus/mat/regression-sparse-read-as-data.mat: Mat_VarRead allocated 3 GB for a 368-byte file).
  const std::string sparse_flags = le32(6) + le32(8) + le32(5) + le32(0);
  const std::string dims_769x8 = le32(5) + le32(8) + le32(769) + le32(8);
  const std::string sparse = file("sparse.mat", le32(14) + le32(64) + sparse_flags + dims_769x8 + name + data);
  EXPECT_EQ(mat_variable_names(sparse), std::vector<std::string>{"x"});
  EXPECT_EQ(error_of([&] { read_mat_variable(sparse, "x"); }), sparse + ": variable 'x' is not a numeric array");
}

TEST(Csv, EmptyCellsAreAnErrorOnlyInTheColumnsUsed) {
  // The layout of the Cascaded Tanks benchmark file: a trailing comma on every line and a column ("Ts") that is
  // filled only in the first row.
  const std::string text = "\"u\",\"y\",\"Ts\",\n1,2,4,\n3,4,,\n5,6,,\n";
  const CsvTable t = parse_csv(text, "tanks.csv");
  EXPECT_EQ(t.names, (std::vector<std::string>{"u", "y", "Ts"}));
  EXPECT_TRUE(std::isnan(t.values(1, 2)));
  DataSpec s;
  s.inputs = {"u"};
  s.outputs = {"y"};
  s.ts = 4;
  EXPECT_EQ(iddata_from_table(t, s).y()(2, 0), 6.0);
  s.ts = 0;
  s.time = "Ts";
  EXPECT_EQ(error_of([&] { iddata_from_table(t, s); }), "tanks.csv:3: column 'Ts' (field 3) is empty");
  // A short row is still ragged, not empty.
  EXPECT_EQ(error_of([] { parse_csv("a,b,c\n1,2,3\n1,2\n", "r.csv"); }), "r.csv:3: expected 3 fields, found 2");
}

TEST(Mat, DamagedLevel4FilesAreRefused) {
  // Found by tests/fuzz/mat_fuzz: a file without a level 5 header is read by libmatio as level 4, whose matrix
  // header declared 1.7e9 x 1.7e9 values (1.9 GB resident before this check).
  const std::string p = test::temp_path("v4.mat");
  std::ofstream(p, std::ios::binary) << std::string(4, '\0') << std::string(100, 'e') << std::string(130, '4');
  EXPECT_NE(error_of([&] { mat_variable_names(p); }).find("not a valid level 4 file"), std::string::npos);
  // tests/fuzz/corpus/mat/regression-v4-negative-dimension.mat: 0 rows x 0xfcffffff columns passed the size check
  // (0 bytes) but libmatio reads the count as a negative int32 -> a 1.8e19 dimension and an Eigen assertion.
  const std::string neg = test::temp_path("v4neg.mat");
  std::ofstream(neg, std::ios::binary) << std::string("\x28\0\0\0\0\0\0\0\xff\xff\xff\xfc\0\0\0\0\x02\0\0\0x\0", 22);
  EXPECT_NE(error_of([&] { read_mat_variable(neg, "x"); }).find("a negative matrix dimension"), std::string::npos);
  // tests/fuzz/corpus/mat/regression-v4-rows-without-columns.mat: 1.26e9 rows x 0 columns (0 bytes) made libmatio
  // allocate 5 GB; no dimension may exceed the file's size.
  const std::string rows = test::temp_path("v4rows.mat");
  std::ofstream(rows, std::ios::binary) << std::string("\x20\0\0\0\0\0\x01\x4b\0\0\0\0\0\0\0\0\x02\0\0\0x\0", 22);
  EXPECT_NE(error_of([&] { read_mat_variable(rows, "x"); }).find("declares 1258356736 x 0 values in a file of 22 bytes"),
            std::string::npos);
  // tests/fuzz/corpus/mat/regression-v4-byte-orders-disagree.mat: the type word is valid only big-endian (40) but
  // says M = 0 (little-endian), so libmatio read the name length 0x00000028 little-endian and allocated 671 MB.
  const std::string mixed = test::temp_path("v4mixed.mat");
  std::ofstream(mixed, std::ios::binary) << std::string("\0\0\0\x28", 4) << std::string(12, '\0')
                                         << std::string("\0\0\0\x28", 4) << std::string(40, 'x');
  EXPECT_NE(error_of([&] { mat_variable_names(mixed); }).find("the matrix type and its byte order disagree"),
            std::string::npos);
  // A consistent big-endian level 4 file (M = 1, type 1000: big-endian doubles) still reads: x = [1.5; -2].
  const std::string be = test::temp_path("v4be.mat");
  std::ofstream(be, std::ios::binary) << std::string("\0\0\x03\xe8\0\0\0\x02\0\0\0\x01\0\0\0\0\0\0\0\x02x\0", 22)
                                      << std::string("\x3f\xf8\0\0\0\0\0\0\xc0\0\0\0\0\0\0\0", 16);
  EXPECT_EQ(read_mat_variable(be, "x"), Eigen::MatrixXd(Eigen::Vector2d(1.5, -2.0)));
}

// The one reader of result files: every model type ctid writes comes back as the same model
// (to the digits JSON keeps: 17 significant, compared to 1e-15 relative), with its method and parameter table; an
// FSF result gets its covariance back; a bare model file is a result without a parameter table.
TEST(Json, EveryModelTypeRoundTripsThroughOneResultReader) {
  const TransferFunction g(Eigen::VectorXd{{1.0, 3.0}}, Eigen::VectorXd{{1.0, 1.2, 4.0}}, 0.25);
  const NarxModel narx({NarxTerm::parse("y(k-1)"), NarxTerm::parse("u(k-1)*y(k-2)")}, Eigen::VectorXd{{0.5, -0.25}}, 0.1);
  const NdeModel nde({NdeTerm::parse("Dy"), NdeTerm::parse("y"), NdeTerm::parse("u")}, Eigen::VectorXd{{0.5, 1.0, -2.0}});
  const Eigen::MatrixXd cov = Eigen::Vector3d(0.01, 0.02, 0.03).asDiagonal();
  const std::vector<AnyModel> models = {g,
                                        MisoModel{{g, TransferFunction(Eigen::VectorXd{{2.0}}, Eigen::VectorXd{{1.0, 0.5}})}},
                                        StateSpace(Eigen::MatrixXd{{-1, 0.5}, {0, -2}}, Eigen::MatrixXd{{1}, {1}},
                                                   Eigen::MatrixXd{{1, 0}, {0, 1}}, Eigen::MatrixXd{{0}, {0}}),
                                        FsfModel(0.1, 20, 3, Eigen::VectorXd{{1.0, 0.2, -0.1}}, cov),
                                        narx,
                                        nde};
  const std::vector<std::string> names = {"transfer_function", "miso", "state_space", "fsf", "narx", "nde"};
  for (size_t i = 0; i < models.size(); ++i) {
    SCOPED_TRACE(names[i]);
    Result<AnyModel> r;
    r.model = models[i];
    r.parameters.names = {"p1", "p2", "p3"};
    r.parameters.values = Eigen::Vector3d(1, 2, 3);
    r.parameters.std = Eigen::Vector3d(0.1, 0.2, 0.3);
    r.parameters.fixed = {false, false, false};
    r.parameters.covariance = cov;
    r.fit.fit_percent = 91.5;
    r.fit.n_samples = 100;
    const ResultFile f = parse_result_file(result_to_json(r, "m" + std::to_string(i)), "f.json");
    EXPECT_EQ(model_type_name(f.result.model), names[i]);
    EXPECT_EQ(f.method, "m" + std::to_string(i));
    EXPECT_FALSE(f.bare);
    EXPECT_EQ(f.result.parameters.values, r.parameters.values);
    EXPECT_EQ(f.result.fit.fit_percent, 91.5);
    // The same model: the same JSON once more.
    EXPECT_EQ(result_to_json(f.result, f.method), result_to_json(r, f.method));
  }
  const Result<AnyModel> fsf{models[3], {}, {}, {}, {}};
  Result<AnyModel> with_cov = fsf;
  with_cov.parameters.values = Eigen::Vector3d(1.0, 0.2, -0.1);
  with_cov.parameters.std = cov.diagonal().cwiseSqrt();
  with_cov.parameters.names = {"theta_0", "re_theta_1", "im_theta_1"};
  with_cov.parameters.fixed = {false, false, false};
  with_cov.parameters.covariance = cov;
  const ResultFile back = parse_result_file(result_to_json(with_cov, "fsf"));
  EXPECT_LT((std::get<FsfModel>(back.result.model).covariance() - cov).norm(), 1e-15);
  // Bare model files: NARX/NDE terms become the parameters (no std); linear models have none.
  const ResultFile bare = parse_result_file(R"J({"type": "narx", "ts": 0.1, "terms": [{"name": "y(k-1)", "value": 0.5}]})J");
  EXPECT_TRUE(bare.bare);
  EXPECT_EQ(bare.result.parameters.names, std::vector<std::string>{"y(k-1)"});
  EXPECT_TRUE(std::isnan(bare.result.parameters.std(0)));
  EXPECT_EQ(parse_result_file(R"({"type": "transfer_function", "num": [1], "den": [1, 2]})").result.parameters.size(), 0);
  // An unknown type names the known ones.
  EXPECT_NE(error_of([] { parse_result_file(R"({"type": "arx", "a": [1]})", "x.json"); })
                .find("x.json: model type \"arx\" is not one ctid knows (transfer_function, miso, state_space, fsf"),
            std::string::npos);
}

// The exact model text Python's pickle uses: doubles that have no short decimal form read back bit for
// bit, an NDE keeps its coefficients (the file form normalises y's to +1), an FSF model its covariance.
TEST(Json, TheExactModelTextReadsBackBitForBit) {
  const double awkward[] = {0.1 + 0.2, 1.0 / 3.0, 1e-300, 3.141592653589793, -2.0 / 7.0};
  const NdeModel nde({NdeTerm::parse("Dy"), NdeTerm::parse("y"), NdeTerm::parse("u")},
                     Eigen::VectorXd{{awkward[0], 3.0, awkward[1]}});
  const NdeModel nde_back = std::get<NdeModel>(parse_result_file(any_model_to_json(nde, true)).result.model);
  EXPECT_EQ(nde_back.coefficients(), nde.coefficients());  // exact equality: every bit
  EXPECT_EQ(std::get<NdeModel>(parse_result_file(any_model_to_json(nde)).result.model).coefficient("y"), 1.0);
  const TransferFunction g(Eigen::VectorXd{{awkward[2], awkward[3]}}, Eigen::VectorXd{{1.0, awkward[4], awkward[1]}},
                           awkward[0]);
  const auto g_back = std::get<TransferFunction>(parse_result_file(any_model_to_json(g, true, -1)).result.model);
  EXPECT_EQ(g_back.num().coefficients(), g.num().coefficients());
  EXPECT_EQ(g_back.den().coefficients(), g.den().coefficients());
  EXPECT_EQ(g_back.io_delay(), g.io_delay());
  const Eigen::MatrixXd cov = Eigen::Vector3d(awkward[0], awkward[1], awkward[3]).asDiagonal();
  const FsfModel fsf(0.1, 20, 3, Eigen::VectorXd{{1.0, awkward[1], -0.1}}, cov);
  const auto fsf_back = std::get<FsfModel>(parse_result_file(any_model_to_json(fsf, true)).result.model);
  EXPECT_EQ(fsf_back.covariance(), cov);
  EXPECT_EQ(fsf_back.theta(), fsf.theta());
}
