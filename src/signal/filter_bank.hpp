// ctid internal — a filter bank of derivative_recursion (ctid/signal/prefilter.hpp) with a compile-time number of
// states, for the estimators that stream a uniformly sampled record: each sample's row of filtered derivatives is made
// and used at once, so a pass reads the signal and writes nothing that grows with the record. The recursion is
// filtered_derivatives' own (exact for the ZOH or FOH input it was made for).
#pragma once

#include "ctid/core/check.hpp"
#include "ctid/signal/prefilter.hpp"

namespace ctid::signal_detail {

// S states (the per-sample loops unroll); rows of up to 2 S + 1 derivatives.
template <int S>
struct Bank {
  double P[S * S], G0[S], G1[S], C[(2 * S + 1) * S], D[2 * S + 1], x[S] = {}, row[2 * S + 1];
  int m;
  explicit Bank(const DerivativeRecursion& r) : m(static_cast<int>(r.C.rows())) {
    CTID_ASSERT(r.Phi.rows() == S && m <= 2 * S + 1);
    for (int i = 0; i < S; ++i) {
      for (int l = 0; l < S; ++l) P[i * S + l] = r.Phi(i, l);
      G0[i] = r.G0(i);
      G1[i] = r.G1(i);
    }
    for (int j = 0; j < m; ++j) {
      for (int i = 0; i < S; ++i) C[j * S + i] = r.C(j, i);
      D[j] = r.D(j);
    }
  }
  // The row of derivatives at the current sample, whose input value is v.
  const double* at(double v) {
    for (int j = 0; j < m; ++j) {
      double acc = D[j] * v;
      for (int i = 0; i < S; ++i) acc += C[j * S + i] * x[i];
      row[j] = acc;
    }
    return row;
  }
  // To the next sample (input v now, v_next there).
  void advance(double v, double v_next) {
    double xn[S];
    const double dv = v_next - v;
    for (int i = 0; i < S; ++i) {
      double acc = G0[i] * v + G1[i] * dv;
      for (int l = 0; l < S; ++l) acc += P[i * S + l] * x[l];
      xn[i] = acc;
    }
    for (int i = 0; i < S; ++i) x[i] = xn[i];
  }
};

// f.template operator()<n>() for the model order n in 1..8 (the orders the streaming passes are compiled for);
// false for another order.
template <class F>
bool with_order(int n, F&& f) {
  switch (n) {
    case 1: f.template operator()<1>(); return true;
    case 2: f.template operator()<2>(); return true;
    case 3: f.template operator()<3>(); return true;
    case 4: f.template operator()<4>(); return true;
    case 5: f.template operator()<5>(); return true;
    case 6: f.template operator()<6>(); return true;
    case 7: f.template operator()<7>(); return true;
    case 8: f.template operator()<8>(); return true;
    default: return false;
  }
}

}  // namespace ctid::signal_detail
