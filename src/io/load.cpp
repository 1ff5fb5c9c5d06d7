#include "ctid/io/load.hpp"

#include <cctype>
#include <cmath>

#include "ctid/core/check.hpp"
#include "ctid/io/mat.hpp"

namespace ctid {

namespace {

void check_spec(const DataSpec& s, const std::string& source) {
  CTID_REQUIRE(!s.outputs.empty(), "{}: no output column selected", source);
  CTID_REQUIRE(s.time.empty() != (s.ts == 0.0), "{}: give either a time column or a sampling period Ts (not {})", source,
               s.time.empty() ? "neither" : "both");
  CTID_REQUIRE(!(s.ts < 0) && std::isfinite(s.ts), "{}: the sampling period must be positive (got Ts = {})", source, s.ts);
}

IdData assemble(const Eigen::MatrixXd& u, const Eigen::MatrixXd& y, const Eigen::VectorXd* t, const DataSpec& s,
                const std::string& source, const std::vector<int>* lines) {
  IdData d;
  if (t) {
    for (Eigen::Index k = 1; k < t->size(); ++k)
      if (!((*t)(k) > (*t)(k - 1))) {
        const std::string where = lines ? detail::format("{}:{}", source, (*lines)[k]) : detail::format("{}: sample {}", source, k);
        throw FileError(detail::format("{}: time column '{}' is not strictly increasing ({} after {})", where, s.time,
                                       (*t)(k), (*t)(k - 1)));
      }
    d = IdData::from_times(u, y, *t);
  } else {
    d = IdData(u, y, s.ts);
  }
  d.set_intersample(s.intersample);
  d.set_input_names(s.inputs);
  d.set_output_names(s.outputs);
  return d;
}

}  // namespace

namespace {
// The same column selected twice (by name or position) would fit a spurious channel: refused. Inputs among
// themselves, outputs among themselves, and the time column against both.
template <class Key>
void check_distinct(const DataSpec& s, const std::string& source, Key key) {
  auto twice = [&](const std::vector<std::string>& v, const char* what) {
    for (std::size_t i = 0; i < v.size(); ++i)
      for (std::size_t k = 0; k < i; ++k)
        if (key(v[i]) == key(v[k]))
          throw ColumnSelectionError(
              detail::format("{}: {} '{}' and '{}' are the same column; select each once", source, what, v[k], v[i]));
  };
  twice(s.inputs, "inputs");
  twice(s.outputs, "outputs");
  if (s.time.empty()) return;
  for (const auto* v : {&s.inputs, &s.outputs})
    for (const auto& n : *v)
      if (key(n) == key(s.time))
        throw ColumnSelectionError(
            detail::format("{}: '{}' is the time column; it cannot also be an input or output", source, n));
}
}  // namespace

bool is_mat_file(const std::string& path) {
  if (path.size() <= 4) return false;
  std::string ext = path.substr(path.size() - 4);
  for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".mat";
}

IdData iddata_from_table(const CsvTable& tab, const DataSpec& s) {
  check_spec(s, tab.source);
  check_distinct(s, tab.source, [&](const std::string& n) { return tab.column(n); });
  const Eigen::Index N = tab.values.rows();
  // Empty cells are NaN in the table; a used column must have none.
  std::vector<std::string> used = s.inputs;
  used.insert(used.end(), s.outputs.begin(), s.outputs.end());
  if (!s.time.empty()) used.push_back(s.time);
  {
    for (const auto& name : used) {
      const int c = tab.column(name);
      for (Eigen::Index k = 0; k < N; ++k)
        if (std::isnan(tab.values(k, c)))
          throw FileError(detail::format("{}:{}: column '{}' (field {}) is empty", tab.source,
                                         k < static_cast<Eigen::Index>(tab.line_numbers.size()) ? tab.line_numbers[k] : k + 1,
                                         tab.names[c], c + 1));
    }
  }
  Eigen::MatrixXd u(N, s.inputs.size()), y(N, s.outputs.size());
  for (std::size_t j = 0; j < s.inputs.size(); ++j) u.col(j) = tab.values.col(tab.column(s.inputs[j]));
  for (std::size_t j = 0; j < s.outputs.size(); ++j) y.col(j) = tab.values.col(tab.column(s.outputs[j]));
  if (!s.time.empty()) {
    const Eigen::VectorXd t = tab.values.col(tab.column(s.time));
    return assemble(u, y, &t, s, tab.source, &tab.line_numbers);
  }
  return assemble(u, y, nullptr, s, tab.source, nullptr);
}

IdData load_iddata(const std::string& path, const DataSpec& s) {
  if (!is_mat_file(path)) return iddata_from_table(read_csv(path, s.csv), s);
  check_spec(s, path);
  check_distinct(s, path, [](const std::string& n) { return n; });
  auto vec = [&](const std::string& name) {
    const Eigen::MatrixXd m = read_mat_variable(path, name);
    if (m.rows() != 1 && m.cols() != 1)
      throw FileError(detail::format("{}: variable '{}' is {}x{}; a vector is expected", path, name, m.rows(), m.cols()));
    return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(m.data(), m.size()));
  };
  std::vector<Eigen::VectorXd> ins, outs;
  for (const auto& n : s.inputs) ins.push_back(vec(n));
  for (const auto& n : s.outputs) outs.push_back(vec(n));
  const Eigen::Index N = outs[0].size();
  auto check_len = [&](const Eigen::VectorXd& v, const std::string& name) {
    if (v.size() != N)
      throw FileError(detail::format("{}: variable '{}' has {} samples but '{}' has {}", path, name, v.size(), s.outputs[0], N));
  };
  Eigen::MatrixXd u(N, ins.size()), y(N, outs.size());
  for (std::size_t j = 0; j < ins.size(); ++j) { check_len(ins[j], s.inputs[j]); u.col(j) = ins[j]; }
  for (std::size_t j = 0; j < outs.size(); ++j) { check_len(outs[j], s.outputs[j]); y.col(j) = outs[j]; }
  for (Eigen::Index j = 0; j < u.cols(); ++j)
    for (Eigen::Index k = 0; k < N; ++k)
      if (!std::isfinite(u(k, j))) throw FileError(detail::format("{}: variable '{}' sample {} is not finite", path, s.inputs[j], k));
  for (Eigen::Index j = 0; j < y.cols(); ++j)
    for (Eigen::Index k = 0; k < N; ++k)
      if (!std::isfinite(y(k, j))) throw FileError(detail::format("{}: variable '{}' sample {} is not finite", path, s.outputs[j], k));
  if (!s.time.empty()) {
    const Eigen::VectorXd t = vec(s.time);
    check_len(t, s.time);
    return assemble(u, y, &t, s, path, nullptr);
  }
  return assemble(u, y, nullptr, s, path, nullptr);
}

}  // namespace ctid
