#include "ctid/estimate/orders.hpp"

#include "ctid/core/check.hpp"

namespace ctid {

void TfOrders::validate(bool allow_biproper) const {
  CTID_REQUIRE_OPTION(nf >= 1, "orders: nf (model order) must be >= 1 (got {})", nf);
  CTID_REQUIRE_OPTION(nb >= 1, "orders: nb (number of numerator coefficients) must be >= 1 (got {})", nb);
  const int max_nb = nf + (allow_biproper ? 1 : 0);
  CTID_REQUIRE_OPTION(nb <= max_nb, "orders: nb = {} exceeds {} for nf = {} ({} model required)", nb, max_nb, nf,
                      allow_biproper ? "proper" : "strictly proper");
  CTID_REQUIRE_OPTION(nk >= 0, "orders: nk (input delay in samples) must be >= 0 (got {})", nk);
}

}  // namespace ctid
