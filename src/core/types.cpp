#include "ctid/core/types.hpp"

#include "ctid/core/check.hpp"

namespace ctid {

int ParameterSet::index(const std::string& name) const {
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<int>(i);
  std::string known;
  for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
  throw InvalidArgument(detail::format("no parameter named '{}' (parameters: {})", name, known));
}

}  // namespace ctid
