// libFuzzer target for the MATLAB .mat reader (libmatio through io/mat.cpp and load_iddata). The
// input is written to a temporary file (matio reads files); any input must either load or throw
// ctid::FileError / ctid::InvalidArgument.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "ctid/core/error.hpp"
#include "ctid/io/load.hpp"
#include "ctid/io/mat.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = "/tmp/ctid_mat_fuzz_" + std::to_string(getpid()) + ".mat";
  if (FILE* f = std::fopen(path.c_str(), "wb")) {
    std::fwrite(data, 1, size, f);
    std::fclose(f);
  } else {
    return 0;
  }
  try {
    const auto names = ctid::mat_variable_names(path);
    if (names.size() >= 2) {
      ctid::DataSpec spec;
      spec.inputs = {names[0]};
      spec.outputs = {names[1]};
      spec.ts = 0.1;
      (void)ctid::load_iddata(path, spec);
    }
  } catch (const ctid::FileError&) {
  } catch (const ctid::InvalidArgument&) {
  }
  return 0;
}
