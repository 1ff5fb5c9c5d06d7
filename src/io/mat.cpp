#include "ctid/io/mat.hpp"

#include <zlib.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstdio>
#include <dlfcn.h>
#include <fstream>
#include <iterator>
#include <vector>

#include <matio.h>

#include "ctid/core/check.hpp"
#include "ctid/io/file.hpp"

namespace ctid {

namespace {
// Structural check of a level-5 MAT file before libmatio reads it: libmatio trusts the sizes declared in
// the file and allocates them (a damaged 177-byte file asked for 7.5 GB; found by tests/fuzz/mat_fuzz).
// Every element must fit in its parent, nested miMATRIX elements are checked recursively, compressed
// elements are inflated (zlib) and checked, and the dimensions of a non-sparse array cannot exceed the
// bytes that follow them. Level 7.3 (HDF5) files are left to HDF5.
class V5Checker {
 public:
  V5Checker(const std::string& path, bool swap) : path_(path), swap_(swap) {}
  void sequence(const unsigned char* p, std::size_t n, int depth, bool top) const {
    if (depth > 32) bad("elements nested more than 32 deep");
    std::size_t i = 0;
    while (i < n) {
      if (n - i < 4) bad("an element tag is cut off");
      const std::uint32_t w0 = u32(p + i);
      std::uint32_t type, size;
      std::size_t header, span;
      if (!top && (w0 >> 16) != 0) {  // small data element: 4-byte tag, up to 4 bytes of data
        type = w0 & 0xffffu;
        size = w0 >> 16;
        if (size > 4) bad("a small data element declares more than 4 bytes");
        header = 4;
        span = 8;
      } else {
        if (n - i < 8) bad("an element tag is cut off");
        type = w0;
        size = u32(p + i + 4);
        header = 8;
        span = 8 + ((static_cast<std::size_t>(size) + 7) / 8) * 8;
      }
      if (size > n - i - header) bad(detail::format("an element declares {} bytes but only {} remain", size, n - i - header));
      const unsigned char* body = p + i + header;
      if (type == 14) {  // miMATRIX: array flags, dimensions, name, data
        matrix(body, size, depth + 1);
      } else if (type == 15) {
        if (!top) bad("a compressed element inside an array");
        const std::vector<unsigned char> inflated = inflate(body, size);
        sequence(inflated.data(), inflated.size(), depth + 1, true);
      } else if (top) {
        bad(detail::format("element type {} at the top level", type));
      }
      i += std::min(span, n - i);
    }
  }

 private:
  void matrix(const unsigned char* p, std::size_t n, int depth) const {
    if (n == 0) return;  // an empty cell or struct field
    // Array flags (class in the low byte), then the dimensions: check their product against the rest.
    std::size_t i = 0;
    auto next = [&](std::uint32_t* type, std::uint32_t* size) -> const unsigned char* {
      if (n - i < 8) bad("an array header is cut off");
      const std::uint32_t w0 = u32(p + i);
      const unsigned char* body;
      if ((w0 >> 16) != 0) {
        *type = w0 & 0xffffu;
        *size = w0 >> 16;
        if (*size > 4) bad("a small data element declares more than 4 bytes");
        body = p + i + 4;
        i += 8;
      } else {
        *type = w0;
        *size = u32(p + i + 4);
        if (*size > n - i - 8) bad(detail::format("an array part declares {} bytes but only {} remain", *size, n - i - 8));
        body = p + i + 8;
        i += std::min(n - i, 8 + ((static_cast<std::size_t>(*size) + 7) / 8) * 8);
      }
      return body;
    };
    std::uint32_t type, size;
    const unsigned char* flags = next(&type, &size);
    if (size < 4) bad("array flags are cut off");
    const std::uint32_t cls = u32(flags) & 0xffu;
    const unsigned char* dims = next(&type, &size);
    if (type != 5 || size % 4 != 0 || size == 0) bad("array dimensions are not int32");
    double count = 1;
    for (std::uint32_t k = 0; k < size; k += 4) {
      const auto d = static_cast<std::int32_t>(u32(dims + k));
      if (d < 0) bad("a negative array dimension");
      if (cls != 5 && static_cast<double>(d) > static_cast<double>(n) + 8)  // also when another dimension is 0
        bad(detail::format("an array dimension of {} in {} bytes", d, n));
      count *= d;
    }
    if (cls != 5 && count > static_cast<double>(n - i) + 8) bad(detail::format("an array of {} elements in {} bytes", count, n - i));
    sequence(p + i, n - i, depth, false);  // name and data parts (nested arrays for cells and structs)
  }
  std::vector<unsigned char> inflate(const unsigned char* p, std::size_t n) const {
    constexpr std::size_t kMax = std::size_t{1} << 31;
    std::vector<unsigned char> out;
    z_stream z{};
    if (inflateInit(&z) != Z_OK) bad("zlib cannot start");
    z.next_in = const_cast<unsigned char*>(p);
    z.avail_in = static_cast<uInt>(n);
    int rc = Z_OK;
    while (rc != Z_STREAM_END) {
      if (out.size() >= kMax) {
        inflateEnd(&z);
        bad("a compressed element inflates to more than 2 GB");
      }
      const std::size_t old = out.size();
      out.resize(old + 65536);
      z.next_out = out.data() + old;
      z.avail_out = 65536;
      rc = ::inflate(&z, Z_NO_FLUSH);
      out.resize(old + 65536 - z.avail_out);
      if (rc != Z_OK && rc != Z_STREAM_END) {
        inflateEnd(&z);
        bad("a compressed element is damaged");
      }
      if (rc == Z_OK && z.avail_in == 0 && z.avail_out != 0) {
        inflateEnd(&z);
        bad("a compressed element is cut off");
      }
    }
    inflateEnd(&z);
    return out;
  }
  std::uint32_t u32(const unsigned char* b) const {
    const std::uint32_t v = static_cast<std::uint32_t>(b[0]) | static_cast<std::uint32_t>(b[1]) << 8 |
                            static_cast<std::uint32_t>(b[2]) << 16 | static_cast<std::uint32_t>(b[3]) << 24;
    return swap_ ? __builtin_bswap32(v) : v;
  }
  [[noreturn]] void bad(const std::string& what) const {
    throw FileError(detail::format("cannot read '{}' as a MATLAB .mat file: {} (the file is truncated or damaged)", path_, what));
  }
  std::string path_;
  bool swap_;
};

// Level 4 files (no header): a sequence of matrices, each a 20-byte header (type MOPT, rows, columns,
// imaginary flag, name length) followed by the name and rows x columns values (x 2 when complex).
void check_v4(const std::string& path, const std::vector<unsigned char>& b) {
  auto bad = [&](const std::string& what) {
    throw FileError(detail::format("cannot read '{}' as a MATLAB .mat file: {}", path, what));
  };
  std::size_t i = 0;
  while (i < b.size()) {
    if (b.size() - i < 20) bad("not a level 5 file, and not a valid level 4 file (a header is cut off)");
    auto word = [&](std::size_t k, bool big) {
      const unsigned char* p = b.data() + i + 4 * k;
      return big ? std::uint32_t(p[3]) | std::uint32_t(p[2]) << 8 | std::uint32_t(p[1]) << 16 | std::uint32_t(p[0]) << 24
                 : std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
    };
    // libmatio reads the type word MOPT in either byte order (whichever is <= 4052), but the other header words
    // in the byte order its M digit names (0 little-endian, 1 big-endian): a file whose two orders disagree
    // made it allocate a 671 MB name (tests/fuzz/corpus/mat/regression-v4-byte-orders-disagree.mat).
    constexpr bool kHostBig = std::endian::native == std::endian::big;
    const bool read_big = kHostBig != (word(0, kHostBig) > 4052);  // libmatio swaps MOPT when out of range
    const std::uint32_t mopt = word(0, read_big);
    if (mopt > 1052 || (mopt / 10) % 10 > 5)
      bad("not a level 5 file, and not a valid level 4 file (bad matrix type)");
    const bool big = mopt >= 1000;  // M = 1: IEEE big-endian
    if (big != read_big)
      bad("not a level 5 file, and not a valid level 4 file (the matrix type and its byte order disagree)");
    const std::uint32_t rows = word(1, big), cols = word(2, big), imag = word(3, big), name = word(4, big);
    if (imag > 1) bad("not a level 5 file, and not a valid level 4 file (bad matrix type)");
    // libmatio reads the sizes as signed 32-bit numbers (a negative one became a 1.8e19 dimension), and it
    // allocates by the row count even when there are no columns (5 GB for a 126-byte file): no dimension may
    // exceed the file's size.
    if (rows > 0x7fffffffu || cols > 0x7fffffffu)
      bad("not a level 5 file, and not a valid level 4 file (a negative matrix dimension)");
    if (rows > b.size() || cols > b.size())
      bad(detail::format("a level 4 matrix declares {} x {} values in a file of {} bytes", rows, cols, b.size()));
    static constexpr int kSize[] = {8, 4, 4, 2, 2, 1};
    const double bytes = double(rows) * double(cols) * kSize[(mopt / 10) % 10] * (1 + imag) + double(name);
    if (bytes > double(b.size() - i - 20))
      bad(detail::format("a level 4 matrix declares {} bytes but only {} remain (the file is truncated or damaged)",
                         bytes, b.size() - i - 20));
    i += 20 + static_cast<std::size_t>(bytes);
  }
}

void check_mat_structure(const std::string& path) {
  std::ifstream f(path, std::ios::binary | std::ios::ate);
  const std::streamoff size = f.tellg();
  std::vector<unsigned char> bytes;
  if (size >= 0) {  // one read of the whole file (byte by byte through a stream iterator was 1 ms per 240 kB)
    bytes.resize(static_cast<std::size_t>(size));
    f.seekg(0);
    f.read(reinterpret_cast<char*>(bytes.data()), size);
    bytes.resize(static_cast<std::size_t>(f.gcount()));
  } else {  // not seekable (a pipe): as it comes
    f.clear();
    bytes.assign(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
  }
  const bool header = bytes.size() >= 128;
  const bool le = header && bytes[126] == 'I' && bytes[127] == 'M', be = header && bytes[126] == 'M' && bytes[127] == 'I';
  if (!le && !be) return check_v4(path, bytes);
  const unsigned version = le ? bytes[124] | bytes[125] << 8 : bytes[125] | bytes[124] << 8;
  if (version == 0x0200) return;  // level 7.3 (HDF5): left to HDF5
  // Any other version word would be read by libmatio as level 5 without this check (a fuzz input with
  // version 0x0110 made it allocate 2 GB).
  if (version != 0x0100) {
    char hex[16];
    std::snprintf(hex, sizeof hex, "0x%04x", version);
    throw FileError(detail::format("cannot read '{}' as a MATLAB .mat file: unknown version {} in the header", path, hex));
  }
  V5Checker(path, be).sequence(bytes.data() + 128, bytes.size() - 128, 0, true);
}

// The library never prints: libmatio's own log messages are dropped (its failures come back as
// return values, which become FileError), and so is the HDF5 error stack that a damaged level 7.3 file makes
// HDF5 print (29-69 lines). H5Eset_auto2 is looked up at run time in the HDF5 that libmatio loaded, so ctid
// does not link HDF5 itself; when it is absent there is nothing to silence.
void quiet_matio_and_hdf5() {
  static const bool done = [] {
    Mat_LogInitFunc("ctid", [](int, char*) {});
    using SetAuto = int (*)(std::int64_t, void*, void*);
    if (void* f = dlsym(RTLD_DEFAULT, "H5Eset_auto2")) reinterpret_cast<SetAuto>(f)(0 /* H5E_DEFAULT */, nullptr, nullptr);
    return true;
  }();
  (void)done;
}

struct MatFile {
  mat_t* m = nullptr;
  explicit MatFile(const std::string& path) {
    require_readable_regular_file(path);
    quiet_matio_and_hdf5();
    check_mat_structure(path);
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
  auto missing = [&] {
    std::string known;
    for (const auto& n : mat_variable_names(path)) known += (known.empty() ? "" : ", ") + n;
    if (known.empty())
      throw FileError(detail::format("{}: no readable variable (the file is empty, truncated or damaged)", path));
    throw FileError(detail::format("{}: no variable named '{}' (variables: {})", path, name, known));
  };
  struct Guard {
    matvar_t* v;
    ~Guard() { if (v) Mat_VarFree(v); }
  };
  // The header first: only a real numeric matrix has its data read (libmatio allocated 3 GB for the
  // declared parts of a damaged sparse array in a 368-byte file; found by tests/fuzz/mat_fuzz).
  {
    const Guard info{Mat_VarReadInfo(f.m, name.c_str())};
    if (!info.v) missing();
    const matvar_t* v = info.v;
    if (v->rank != 2) throw FileError(detail::format("{}: variable '{}' has {} dimensions (2 expected)", path, name, v->rank));
    if (v->class_type < MAT_C_DOUBLE || v->class_type > MAT_C_UINT64)
      throw FileError(detail::format("{}: variable '{}' is not a numeric array", path, name));
    if (v->isComplex) throw FileError(detail::format("{}: variable '{}' is complex (real expected)", path, name));
  }
  const Guard guard{Mat_VarRead(f.m, name.c_str())};
  if (!guard.v) missing();
  const matvar_t* v = guard.v;
  if (v->dims[0] > 0x7fffffffu || v->dims[1] > 0x7fffffffu)  // the structure checks should make this impossible
    throw FileError(detail::format("{}: variable '{}' declares {} x {} values (the file is damaged)", path, name, v->dims[0],
                                   v->dims[1]));
  const double values = double(v->dims[0]) * double(v->dims[1]);
  if (v->rank != 2 || v->isComplex || (values > 0 && (v->data == nullptr || double(v->nbytes) < values * v->data_size)))
    throw FileError(detail::format("{}: variable '{}' cannot be read (the file is damaged)", path, name));
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

void write_mat(const std::string& out, const std::map<std::string, Eigen::MatrixXd>& vars) {
  const std::string path = resolve_output_file(out);
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
