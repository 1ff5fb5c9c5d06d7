// libFuzzer target for the JSON model and result readers (linear models, TF and MISO results, NARX and NDE models;
// grey-box model files and any result file). Any input must either be read or throw ctid::FileError / ctid::InvalidArgument.
#include <cstddef>
#include <cstdint>
#include <string>

#include "ctid/core/error.hpp"
#include "ctid/io/json.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  auto guarded = [](auto&& f) {
    try {
      f();
    } catch (const ctid::FileError&) {
    } catch (const ctid::InvalidArgument&) {
    }
  };
  guarded([&] { (void)ctid::parse_model_json(text, "<fuzz>"); });
  guarded([&] { (void)ctid::parse_result_json(text, "<fuzz>"); });
  guarded([&] { (void)ctid::parse_miso_result_json(text, "<fuzz>"); });
  guarded([&] { (void)ctid::parse_narx_json(text, "<fuzz>"); });
  guarded([&] { (void)ctid::parse_nde_json(text, "<fuzz>"); });
  guarded([&] { (void)ctid::parse_greybox_json(text, "<fuzz>"); });
  guarded([&] { (void)ctid::parse_result_file(text, "<fuzz>"); });
  return 0;
}
