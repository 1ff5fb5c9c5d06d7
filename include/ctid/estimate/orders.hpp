// ctid — transfer-function structure [nb nf nk] in CONTSID's convention.
#pragma once

namespace ctid {

/// nb: number of numerator coefficients; nf: model order (denominator coefficients
/// after the leading 1); nk: input delay in samples (uniformly sampled data only).
struct TfOrders {
  int nb = 1;
  int nf = 1;
  int nk = 0;
  /// Throws InvalidOptions naming the field: nf >= 1, 1 <= nb <= nf + (allow_biproper ? 1 : 0), nk >= 0.
  void validate(bool allow_biproper = false) const;
  int n_parameters() const { return nb + nf; }
};

}  // namespace ctid
