// libFuzzer target for the CSV/whitespace table reader and the IdData built from it. Any input
// must either give a table (and a record, when it has the columns) or throw ctid::FileError /
// ctid::InvalidArgument; anything else (another exception, a crash, a sanitizer report) is a bug.
// Run: see tests/fuzz/CMakeLists.txt (make fuzz).
#include <cstddef>
#include <cstdint>
#include <string>

#include "ctid/core/error.hpp"
#include "ctid/io/csv.hpp"
#include "ctid/io/load.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const ctid::CsvTable t = ctid::parse_csv(text, "<fuzz>");
    if (t.values.cols() >= 2) {
      ctid::DataSpec spec;
      spec.inputs = {t.names[0]};
      spec.outputs = {t.names[1]};
      spec.ts = 0.1;
      (void)ctid::iddata_from_table(t, spec);
      spec.ts = 0.0;
      spec.time = t.names[0];
      spec.inputs = {};
      (void)ctid::iddata_from_table(t, spec);
    }
  } catch (const ctid::FileError&) {
  } catch (const ctid::InvalidArgument&) {
  }
  return 0;
}
