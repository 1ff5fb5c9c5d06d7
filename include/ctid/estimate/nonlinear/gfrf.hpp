// ctid — generalised frequency response functions (GFRFs) of polynomial NARX models, Billings & Li
// (1999) eqs 11-14 with the corrected Peyton Jones & Billings recursion of BL 11-14:
//   H_n(z_1..z_n) = [1 - sum_k c_10(k) (z_1..z_n)^-k]^-1 { sum c_0n(k) z_1^-k_1 .. z_n^-k_n
//        + sum_{q=1}^{n-1} sum_{p=1}^{n-q} sum c_pq(k) z_{n-q+1}^-k_{p+1} .. z_n^-k_{p+q} H_{n-q,p}(z_1..z_{n-q})
//        + sum_{p=2}^{n} sum c_p0(k) H_{n,p}(z_1..z_n) },
//   H_{n,p}(z_1..z_n) = sum_{i=1}^{n-p+1} H_i(z_1..z_i) H_{n-i,p-1}(z_{i+1}..z_n) (z_1..z_i)^-k_p,
//   H_{n,1}(z_1..z_n) = H_n(z_1..z_n) (z_1..z_n)^-k_1,
// for the process terms (noise terms dropped), c_pq a term with p output and q input factors. The
// symmetric kernel is the mean over the n! orderings of the arguments.
#pragma once

#include <complex>
#include <vector>

#include "ctid/model/narx.hpp"

namespace ctid {

using Complex = std::complex<double>;

/// Asymmetric H_n at z = (z_1..z_n), n = z.size() >= 1. A constant term is ignored (it shifts the
/// operating point, not the kernels). Throws InvalidArgument for an empty z or a zero z_i.
Complex narx_gfrf_asymmetric(const NarxModel& model, const std::vector<Complex>& z);
/// Symmetric H_n (mean over the n! permutations of z).
Complex narx_gfrf(const NarxModel& model, const std::vector<Complex>& z);

/// The NARX kernel read as a continuous-time kernel at s = (s_1..s_n) by kernel invariance (z_i = e^{s_i T}):
/// H_n(e^{s_1 T}, ..)/prod_i Z(s_i) with Z(s) = (1 - e^{-sT})/(sT) when `zoh` (data sampled with a held
/// input: the hold's own response divides out; Z(0) = 1), else H_n(e^{s_1 T}, ..). Symmetric.
Complex narx_gfrf_ct(const NarxModel& model, const std::vector<Complex>& s, bool zoh = true);

/// The zero-order-hold factor Z(s) = (1 - e^{-sT})/(sT), Z(0) = 1.
Complex zoh_factor(Complex s, double T);

}  // namespace ctid
