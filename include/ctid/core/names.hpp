// ctid — the closest valid name, for error messages that suggest one ("did you mean 'tau_grid_size'?"): settings,
// parameter and term names, model-language variables.
#pragma once

#include <string>
#include <vector>

namespace ctid {

/// The closest of `names` to `key`: a name `key` starts (or `key` is NAME.something), else the nearest by edit
/// distance; "" when none is within half of key's length + 2.
std::string closest_name(const std::string& key, const std::vector<std::string>& names);

}  // namespace ctid
