// Billings & Li (1999) models shared by the GFRF, KIA and NDE output-error tests (Billings & Li 1999, eqs 33-34 and Tables 1-3).
#pragma once

#include <string>

#include "ctid/io/json.hpp"
#include "ctid/model/narx.hpp"
#include "ctid/model/nde.hpp"
#include "test_paths.hpp"

/// NARX model (34), process part, as printed (examples/data/bl34_narx.json).
inline ctid::NarxModel bl34() { return ctid::read_narx_json(std::string(CTID_EXAMPLES_DATA_DIR) + "/bl34_narx.json"); }

/// System (33): y + 0.002 Dy + 1e-4 D^2y + u_coef u + 0.1 y^2 + ydy y Dy = 0 (the paper's u_coef = -1, ydy = -0.006).
inline ctid::NdeModel bl33(double ydy = -0.006, double u_coef = -1.0) {
  std::vector<ctid::NdeTerm> t;
  for (const char* s : {"y", "Dy", "D^2y", "u", "y^2", "y*Dy"}) t.push_back(ctid::NdeTerm::parse(s));
  return ctid::NdeModel(t, (Eigen::VectorXd(6) << 1, 0.002, 1e-4, u_coef, 0.1, ydy).finished());
}
