#pragma once
// ctid — the simulated example records the README and docs/ use (`ctid example-data NAME OUT.csv`, Python
// ctid.example_data): each is a known system, a named input design and seeded noise, so every documented command
// can be run verbatim and its answer checked against the truth given in `description`.
#include <string>
#include <vector>

#include <Eigen/Dense>

namespace ctid {

/// One example record: a table (columns named as the docs use them) and what it is.
struct ExampleData {
  std::string name;
  std::string description;            ///< the system, input, sampling and noise: the truth to compare with
  std::vector<std::string> columns;   ///< column names, e.g. {"t", "u", "y"}
  Eigen::MatrixXd values;             ///< one row per sample (or per frequency for "freq")
};

/// The names example_data knows, in the order `ctid example-data --list` prints them.
std::vector<std::string> example_data_names();

/// The example record `name` (deterministic: the same numbers on every machine and run). Throws InvalidArgument
/// naming the known names for any other name.
ExampleData example_data(const std::string& name);

}  // namespace ctid
