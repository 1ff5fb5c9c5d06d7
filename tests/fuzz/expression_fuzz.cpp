// libFuzzer target for the physical-model expression parser. Build with clang:
//   CXX=clang++ cmake -S . -B build-fuzz -DCTID_BUILD_FUZZ=ON -DCTID_BUILD_TESTS=OFF -DCTID_BUILD_APPS=OFF \
//       -DCTID_BUILD_BENCHMARKS=OFF && cmake --build build-fuzz --target expression_fuzz
//   build-fuzz/tests/fuzz/expression_fuzz -max_total_time=60
// Any input must either parse and evaluate, or throw ctid::InvalidArgument; anything else
// (another exception, a crash, a sanitizer report) is a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "ctid/core/error.hpp"
#include "ctid/model/physical_model.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string expr(reinterpret_cast<const char*>(data), size);
  try {
    const std::vector<std::string> names = ctid::PhysicalModel::symbols(expr);
    const ctid::PhysicalModel m(expr, names);
    const Eigen::VectorXd theta = Eigen::VectorXd::LinSpaced(static_cast<Eigen::Index>(names.size()), 0.5, 2.0);
    (void)m.shifted(theta, 0.5);
    (void)m.sensitivities(theta, 0.0);
  } catch (const ctid::InvalidArgument&) {
  }
  return 0;
}
