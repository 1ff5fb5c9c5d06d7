// ctid — MATLAB .mat files (v5, v7, v7.3) through libmatio: named real numeric variables.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Dense>

namespace ctid {

/// Names of the variables in a .mat file. Throws FileError when it cannot be opened.
std::vector<std::string> mat_variable_names(const std::string& path);
/// A real numeric 2-D variable (any numeric class, converted to double). Throws
/// FileError naming the file and variable when it is absent, complex, sparse,
/// non-numeric or has more than 2 dimensions.
Eigen::MatrixXd read_mat_variable(const std::string& path, const std::string& name);
/// Write variables to a new v5 .mat file (atomic: temporary file, then rename).
void write_mat(const std::string& path, const std::map<std::string, Eigen::MatrixXd>& variables);

}  // namespace ctid
