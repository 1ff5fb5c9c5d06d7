#include "ctid/io/mat.hpp"

#include <cstdio>
#include <unistd.h>

#include <matio.h>

#include "ctid/core/check.hpp"

namespace ctid {

namespace {
struct MatFile {
  mat_t* m = nullptr;
  explicit MatFile(const std::string& path) {
    if (access(path.c_str(), R_OK) != 0) throw FileError(detail::format("cannot open '{}': no such readable file", path));
    m = Mat_Open(path.c_str(), MAT_ACC_RDONLY);
    if (!m) throw FileError(detail::format("cannot read '{}' as a MATLAB .mat file", path));
  }
  ~MatFile() { if (m) Mat_Close(m); }
};

template <class T>
void copy_as_double(const void* data, Eigen::MatrixXd& out) {
  const T* p = static_cast<const T*>(data);
  for (Eigen::Index k = 0; k < out.size(); ++k) out.data()[k] = static_cast<double>(p[k]);  // column-major like MATLAB
}
}  // namespace

std::vector<std::string> mat_variable_names(const std::string& path) {
  MatFile f(path);
  std::vector<std::string> names;
  while (matvar_t* v = Mat_VarReadNextInfo(f.m)) {
    if (v->name) names.emplace_back(v->name);
    Mat_VarFree(v);
  }
  return names;
}

Eigen::MatrixXd read_mat_variable(const std::string& path, const std::string& name) {
  MatFile f(path);
  matvar_t* v = Mat_VarRead(f.m, name.c_str());
  if (!v) {
    std::string known;
    for (const auto& n : mat_variable_names(path)) known += (known.empty() ? "" : ", ") + n;
    if (known.empty())
      throw FileError(detail::format("{}: no readable variable (the file is empty, truncated or damaged)", path));
    throw FileError(detail::format("{}: no variable named '{}' (variables: {})", path, name, known));
  }
  struct Guard { matvar_t* v; ~Guard() { Mat_VarFree(v); } } guard{v};
  if (v->rank != 2) throw FileError(detail::format("{}: variable '{}' has {} dimensions (2 expected)", path, name, v->rank));
  if (v->isComplex) throw FileError(detail::format("{}: variable '{}' is complex (real expected)", path, name));
  Eigen::MatrixXd out(static_cast<Eigen::Index>(v->dims[0]), static_cast<Eigen::Index>(v->dims[1]));
  switch (v->class_type) {
    case MAT_C_DOUBLE: copy_as_double<double>(v->data, out); break;
    case MAT_C_SINGLE: copy_as_double<float>(v->data, out); break;
    case MAT_C_INT8: copy_as_double<std::int8_t>(v->data, out); break;
    case MAT_C_UINT8: copy_as_double<std::uint8_t>(v->data, out); break;
    case MAT_C_INT16: copy_as_double<std::int16_t>(v->data, out); break;
    case MAT_C_UINT16: copy_as_double<std::uint16_t>(v->data, out); break;
    case MAT_C_INT32: copy_as_double<std::int32_t>(v->data, out); break;
    case MAT_C_UINT32: copy_as_double<std::uint32_t>(v->data, out); break;
    case MAT_C_INT64: copy_as_double<std::int64_t>(v->data, out); break;
    case MAT_C_UINT64: copy_as_double<std::uint64_t>(v->data, out); break;
    default: throw FileError(detail::format("{}: variable '{}' is not a numeric array", path, name));
  }
  return out;
}

void write_mat(const std::string& path, const std::map<std::string, Eigen::MatrixXd>& vars) {
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  mat_t* m = Mat_CreateVer(tmp.c_str(), nullptr, MAT_FT_MAT5);
  if (!m) throw FileError(detail::format("cannot write '{}'", path));
  bool ok = true;
  for (const auto& [name, value] : vars) {
    size_t dims[2] = {static_cast<size_t>(value.rows()), static_cast<size_t>(value.cols())};
    Eigen::MatrixXd copy = value;
    matvar_t* v = Mat_VarCreate(name.c_str(), MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, copy.data(), MAT_F_DONT_COPY_DATA);
    ok = ok && v && Mat_VarWrite(m, v, MAT_COMPRESSION_NONE) == 0;
    if (v) Mat_VarFree(v);
  }
  Mat_Close(m);
  if (!ok || std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw FileError(detail::format("cannot write '{}'", path));
  }
}

}  // namespace ctid
