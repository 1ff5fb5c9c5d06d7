// ctid — srivc_auto: a transfer function without hand-picked orders (the default of `ctid fit`), and
// srivc_auto_miso, the same for several inputs.
//
// What an expert does first with a new single-input record: SRIVC (Young & Jakeman 1980; estimate/transfer_function/srivc.hpp) for
// every structure nf = 1..nf_max, nb = 1..nf (strictly proper), each once without an input delay and, with
// try_delay, once with SRIVC's delay search (a grid over [delay_min, delay_max], then refinement); the structure of
// least BIC among the usable fits is returned (Schwarz 1978; the delay counts as a parameter, so it is kept only
// when the data show one). A fit is usable as in select_order (estimate/transfer_function/order_selection.hpp): converged, stable, no
// pole beyond ten times the Nyquist frequency, no pole-zero pair cancelling within its confidence region.
#pragma once

#include "ctid/core/types.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/estimate/options.hpp"
#include "ctid/estimate/transfer_function/srivc.hpp"
#include "ctid/model/miso.hpp"
#include "ctid/model/transfer_function.hpp"

namespace ctid {

struct SrivcAutoOptions {
  int nf_max = 3;          ///< largest model order tried (nf = 1..nf_max, nb = 1..nf)
  bool try_delay = true;   ///< also fit each structure with SRIVC's delay search; kept when its BIC is lower
  /// The fits' settings (estimate_delay is set by the route); the delay search on a grid of 40 points (SRIVC's own
  /// default is one per sample period, up to 200: the route runs it for every structure, and the refinement after
  /// the grid finds the delay between its points).
  SrivcOptions srivc = [] {
    SrivcOptions s;
    s.delay_grid = 40;
    return s;
  }();
  void validate() const;
};
/// The settings of SrivcAutoOptions (name, unit, range, default, doc): validate(), the CLI and Python use it.
template <>
const OptionTable<SrivcAutoOptions>& option_table<SrivcAutoOptions>();

/// The least-BIC usable SRIVC fit over the structures above (one input, one output). The result is that fit's, with
/// diagnostics structure_nb, structure_nf, structure_delay (s; 0: fitted without delay) and structure_bic (NaN:
/// not usable) of every structure tried, in the order tried. When no fit is usable the one of least BIC is returned
/// (not usable, its own reason). Throws InvalidArgument for data that are not single-input single-output or too
/// short, InvalidOptions for bad options.
Result<TransferFunction> srivc_auto(const IdData& data, const SrivcAutoOptions& options = {});

/// The same for several inputs (MISO; one output): y = sum_i B_i(s)/A_i(s) e^{-s tau_i} u_i, by backfitting the
/// structures as srivc_miso backfits the parameters (Garnier, Gilson, Young & Huselstein 2007). First each
/// input alone (srivc_auto on that input and the whole output; the other inputs act as noise, which the instruments
/// tolerate when the inputs are not correlated) gives every channel's structure and delay tau_i, and srivc_miso fits
/// all channels together (separate denominators, the delays as SrivcMisoOptions::delays). Then, repeatedly, srivc_auto
/// on each channel's input and the output less the other channels' simulated contributions chooses that channel's
/// structure and delay again; the new joint fit is kept while its BIC is lower (the usable fit first), until the
/// structures repeat (at most 3 rounds). diagnostics.choices says what each round chose. One input: srivc_auto as a
/// one-channel MisoModel. Throws InvalidArgument for data with other than one output or too short, InvalidOptions
/// for bad options.
Result<MisoModel> srivc_auto_miso(const IdData& data, const SrivcAutoOptions& options = {});

}  // namespace ctid
