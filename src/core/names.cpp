// ctid — the closest valid name for an error message (include/ctid/core/names.hpp).
#include "ctid/core/names.hpp"

#include <algorithm>

namespace ctid {

std::string closest_name(const std::string& key, const std::vector<std::string>& names) {
  auto distance = [](const std::string& a, const std::string& b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
      std::size_t diag = row[0];
      row[0] = i;
      for (std::size_t j = 1; j <= b.size(); ++j) {
        const std::size_t up = row[j];
        row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
        diag = up;
      }
    }
    return row[b.size()];
  };
  // A key that starts with, or is contained in, a valid name is taken as that name (tau_grid -> tau_grid_size).
  for (const auto& n : names)
    if (!key.empty() && (n.rfind(key, 0) == 0 || key.rfind(n + ".", 0) == 0)) return n;
  std::string best;
  std::size_t best_d = key.size() / 2 + 2;
  for (const auto& n : names) {
    const std::size_t d = distance(key, n);
    if (d < best_d) {
      best_d = d;
      best = n;
    }
  }
  return best;
}

}  // namespace ctid
