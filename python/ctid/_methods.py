"""ctid's estimators and tools as Python functions with keyword options: the structure as arguments, the fields of the
C++ options struct as keywords of the same names (``ctid.srivc(data, nb=2, nf=2, max_iterations=50)``). Each
function's docstring ends with the settings of the registered method it runs, read from the library's option tables.
Re-exported by the package: call them as ``ctid.srivc``, ``ctid.fsf``, ...."""
import difflib as _difflib

import numpy as _np

from . import _ctid
from ._ctid import (FrequencyData, InputGenerator, InvalidArgument, InvalidOptions, ModalWindow, NarxTerm, methods,
                    settings)


def _enum(enum_cls, value, who, key):
    """An enumeration member from its name (case-insensitive); members pass through."""
    if not isinstance(value, str):
        return value
    members = {name.lower(): m for name, m in enum_cls.__members__.items()}
    if value.lower() not in members:
        raise ValueError(f"{who}: option '{key}' must be one of {', '.join(members)} (got '{value}')")
    return members[value.lower()]


def _check_names(who, keys, names):
    """A TypeError naming the closest of `names` for the first key that is not one of them."""
    for key in keys:
        if key not in names:
            near = _difflib.get_close_matches(key, names, n=1, cutoff=0.6)
            hint = f"; did you mean '{near[0]}'?" if near else ""
            raise TypeError(f"{who}: unknown option '{key}'{hint} (options: {', '.join(names)})")


def _options(cls, who, kwargs):
    """An options struct of type cls from keyword arguments. Structs with a settings table (``cls._names``) convert
    each value in C++ by the setting's kind; the others take nested structs from dicts and enums from names."""
    o = cls()
    names = getattr(cls, "_names", None)
    if names is not None:
        _check_names(who, kwargs, names)
        for key, value in kwargs.items():
            setattr(o, key, value)
        return o
    for key, value in kwargs.items():
        if key.startswith("_") or not hasattr(o, key):
            known = sorted(k for k in dir(o) if not k.startswith("_"))
            raise TypeError(f"{who}: unknown option '{key}' (options: {', '.join(known)})")
        current = getattr(o, key)
        if isinstance(value, dict) and type(current).__module__.startswith("ctid"):  # a nested options struct
            value = _options(type(current), f"{who}.{key}", value)
        elif hasattr(type(current), "__members__"):
            value = _enum(type(current), value, who, key)
        setattr(o, key, value)
    return o


def _terms(cls, terms):
    """Terms from names (parsed here so that a bad name raises InvalidArgument naming the position)."""
    return [t if isinstance(t, cls) else cls(t) for t in terms]


def _runs(method):
    """Marks a function as running the registered method `method` (for one whose name is not the method's): its
    docstring gets that method's settings."""
    def mark(f):
        f._method = method
        return f
    return mark


# ---- estimators with keyword options (names as in C++) ----

def lssvf(data, nb, nf, nk=0, **options):
    """Johansson (1986): least squares on state-variable-filtered signals (options: LssvfOptions). data: an IdData, a
    list of IdData (several experiments), or a FrequencyData — the same criterion in the frequency domain (RJ 45)."""
    return _ctid.lssvf(data, nb, nf, nk, _options(_ctid.LssvfOptions, "lssvf", options))


def ivsvf(data, nb, nf, nk=0, **options):
    """Johansson's regression with instrumental variables (options: IvsvfOptions: the LSSVF settings, max_iterations,
    tolerance)."""
    return _ctid.ivsvf(data, nb, nf, nk, _options(_ctid.IvsvfOptions, "ivsvf", options))


def srivc(data, nb, nf, nk=0, **options):
    """Simplified refined instrumental variables for continuous-time models (options: SrivcOptions). data: an IdData,
    or a list of IdData — several experiments of one system, fitted jointly (one parameter set; transient_time=
    leaves out the start of each record when they do not start at rest)."""
    return _ctid.srivc(data, nb, nf, nk, _options(_ctid.SrivcOptions, "srivc", options))


def srivc_auto(data, **options):
    """A transfer function without hand-picked orders: SRIVC for every nf = 1..nf_max (default 3), nb = 1..nf, each
    with and without a delay search, the usable fit of least BIC (options: SrivcAutoOptions; ctid.settings("srivc_auto")
    lists them). The structures tried are in result.diagnostics.vectors["structure_nb"], "structure_nf",
    "structure_delay" and "structure_bic". The means are not removed: use data.detrend() first. Data with several
    inputs: srivc_auto_miso (each channel's structure and delay, backfitted; a MisoResult; the steps in
    result.diagnostics.choices)."""
    o = _options(_ctid.SrivcAutoOptions, "srivc_auto", options)
    return _ctid.srivc_auto_miso(data, o) if data.nu > 1 else _ctid.srivc_auto(data, o)


def oe(data, nb, nf, nk=0, **options):
    """Continuous-time output error by Levenberg-Marquardt (options: OeOptions). data: an IdData or a list of IdData
    (several experiments of one system, fitted jointly)."""
    return _ctid.oe(data, nb, nf, nk, _options(_ctid.OeOptions, "oe", options))


def tfest(data, nb, nf, nk=0, **options):
    """SRIVC start, then output-error refinement (options: OeOptions). data: an IdData or a list of IdData (several
    experiments of one system, fitted jointly)."""
    return _ctid.tfest(data, nb, nf, nk, _options(_ctid.OeOptions, "tfest", options))


def rls_svf(data, nb, nf, nk=0, **options):
    """Johansson's recursive least squares on filtered signals, run once over the record: the final estimate, its
    simulation fit, no standard deviations (options: RlsSvfOptions; ctid.settings("rls_svf") lists them). data: an
    IdData or a list of IdData (several experiments: the recursion runs over them in turn, the filters restarting)."""
    return _ctid.rls_svf(data, nb, nf, nk, _options(_ctid.RlsSvfOptions, "rls_svf", options))


def srivc_miso(data, orders, **options):
    """SRIVC with several inputs: orders is one (nb, nf, nk) per input (options: SrivcMisoOptions, e.g.
    common_denominator=True, delays=[..] in s). data: an IdData or a list of IdData (several experiments, jointly)."""
    return _ctid.srivc_miso(data, [tuple(o) for o in orders], _options(_ctid.SrivcMisoOptions, "srivc_miso", options))


def srivc_closed_loop(data, reference, nb, nf, nk=0, **options):
    """Closed-loop SRIVC: data holds the plant input and output, reference the reference signal (one value per
    sample); options: ClosedLoopOptions, controller= the known TransferFunction (required). Several experiments of
    one loop: data a list of IdData and reference a list of as many signals (one per record), fitted jointly."""
    if "controller" not in options:
        raise InvalidOptions("srivc_closed_loop: the known controller is required (controller=TransferFunction(...))")
    o = _options(_ctid.ClosedLoopOptions, "srivc_closed_loop", options)
    if isinstance(data, (list, tuple)):
        if not isinstance(reference, (list, tuple)):
            raise InvalidArgument("srivc_closed_loop: with a list of records, reference is a list of as many signals "
                                  "(one per record)")
        return _ctid.srivc_closed_loop(list(data), [_np.asarray(r, dtype=float).ravel() for r in reference], nb, nf,
                                       nk, o)
    return _ctid.srivc_closed_loop(data, _np.asarray(reference, dtype=float).ravel(), nb, nf, nk, o)


def tf_from_frequency(data, nb, nf, **options):
    """Transfer function fitted to frequency-response data (a FrequencyData, or a pair (w, G) of arrays);
    options: FrequencyFitOptions."""
    if not isinstance(data, FrequencyData):
        w, g = data
        data = FrequencyData(_np.asarray(w, dtype=float), _np.asarray(g, dtype=complex))
    return _ctid.tf_from_frequency(data, nb, nf, _options(_ctid.FrequencyFitOptions, "tf_from_frequency", options))


def select_order(data, nb, nf, nk=(0, 0), rank_by="yic", **srivc_options):
    """Rank every structure of the (min, max) ranges nb, nf, nk by SRIVC fits (CONTSID's srivcstruc);
    rank_by: yic, rt2, aic or bic; further keywords are SrivcOptions. Returns OrderCandidates, usable first."""
    o = _options(_ctid.OrderSelectionOptions, "select_order", {"rank_by": rank_by})
    o.srivc = _options(_ctid.SrivcOptions, "select_order", srivc_options)
    return _ctid.select_order(data, tuple(nb), tuple(nf), tuple(nk), o)


def fsf(data, **options):
    """Gawthrop & Wang (2005) frequency-sampling-filter model (options: FsfOptions; T is required)."""
    return _ctid.fsf(data, _options(_ctid.FsfOptions, "fsf", options))


def fsf_from_spectra(U, Y, L, ts, **options):
    """Gawthrop & Wang stage 1 from the one-sided DFTs U, Y (ctid.one_sided_dft(x, L), L >= M + N) of input
    and output records sampled at ts (options: FsfOptions; T is required, b must be 0)."""
    return _ctid.fsf_from_spectra(_np.asarray(U, dtype=complex), _np.asarray(Y, dtype=complex), L, ts,
                                  _options(_ctid.FsfOptions, "fsf_from_spectra", options))


def frols(data, candidates, **options):
    """Polynomial NARX structure selection by FROLS/ERR (options: FrolsOptions; criterion='aic', ...). data: an
    IdData or a list of IdData (several records of one system: one regression of their rows, none across records)."""
    return _ctid.frols(data, _terms(NarxTerm, candidates), _options(_ctid.FrolsOptions, "frols", options))


def narmax(data, candidates, **options):
    """NARMAX by FROLS and extended least squares (options: NarmaxOptions: the FROLS settings, noise_candidates,
    max_noise_terms, iterations, tolerance). data: an IdData or a list of IdData."""
    return _ctid.narmax(data, _terms(NarxTerm, candidates), _options(_ctid.NarmaxOptions, "narmax", options))


def narx(data, **options):
    """The NARX workflow of `ctid fit --method narx`: candidates from degree, ylag, ulag, umin, constant; FROLS with
    an information criterion (criterion='aic' by default); NARMAX when noise_terms > 0 (options: NarxOptions). data: an
    IdData or a list of IdData (several records of one system)."""
    return _ctid.narx(data, _options(_ctid.NarxOptions, "narx", options))


def kia_linear(narx, **options):
    """Kernel Invariance Algorithm, linear stage (options: KiaLinearOptions: y_order, u_order, points, max, ...)."""
    return _ctid.kia_linear(narx, _options(_ctid.KiaLinearOptions, "kia_linear", options))


def kia_quadratic(narx, linear, **options):
    """Kernel Invariance Algorithm, quadratic stage (options: KiaQuadraticOptions; candidates=['y^2', ...])."""
    return _ctid.kia_quadratic(narx, linear, _options(_ctid.KiaQuadraticOptions, "kia_quadratic", options))


def kia_cubic(narx, model, **options):
    """Kernel Invariance Algorithm, cubic stage (options: KiaCubicOptions; candidates=['y^3', ...])."""
    return _ctid.kia_cubic(narx, model, _options(_ctid.KiaCubicOptions, "kia_cubic", options))


def kia(data, narx, **options):
    """The whole Kernel Invariance workflow (as `ctid fit --method kia`): stages, stacking, the check that the
    equation reproduces its NARX model, and the output-error refinement. Options: KiaOptions with the CLI's names,
    e.g. y_order=2, quadratic=['y^2', 'y*Dy'], cubic=['y^3'], qpoints=70, refine=True (ctid.settings('kia')).
    A stage without candidates runs when the NARX model has terms of its degree, with every product of that degree
    (ctid.kia_product_candidates) pruned by ERR at 0.01 % (err_threshold); run.result().diagnostics.choices says so.
    data: an IdData, or a list of IdData (several experiments of one system: the NARX model should come from all of
    them, e.g. ctid.narx([a, b], ...)). Returns a KiaRun; its result() is the answer."""
    return _ctid.kia(data, narx, _options(_ctid.KiaOptions, "kia", options))


def nde_oe(data, initial, **options):
    """Output-error refinement of an NDE model's coefficients and initial state (options: NdeOeOptions). data: an
    IdData or a list of IdData (several experiments: shared coefficients, each record's own initial state)."""
    return _ctid.nde_oe(data, initial, _options(_ctid.NdeOeOptions, "nde_oe", options))


def greybox_model(model):
    """A GreyboxModel from a dict with the model file's members (type, inputs, states, outputs, parameters,
    equations, initial; docs/methods/greybox.md), a path to such a JSON file, or a GreyboxModel (returned as is)."""
    import json as _json
    import os as _os
    if isinstance(model, _ctid.GreyboxModel):
        return model
    if isinstance(model, dict):
        return _ctid.parse_greybox_json(_json.dumps({"type": "greybox", **model}), "<dict>")
    if isinstance(model, (str, _os.PathLike)):
        return _ctid.read_greybox_json(_os.fspath(model))
    raise TypeError(f"greybox: the model must be a dict, a path or a GreyboxModel (got {type(model).__name__})")


def greybox(data, model, **options):
    """Nonlinear grey-box identification by output error with exact sensitivities (as `ctid fit --method greybox`).
    data: an IdData whose inputs and outputs are the model's, in its order, or a list of IdData (several experiments:
    one parameter set, each record's own initial state). model: a dict, a JSON path or a GreyboxModel. Options:
    GreyboxOptions (ctid.settings('greybox')), e.g. starts=8, seed=1, fixed={'g': 9.81}, bounds={'k1': (0, 1)}."""
    return _ctid.greybox(data, greybox_model(model), _options(_ctid.GreyboxOptions, "greybox", options))


def subspace(data, nx=0, **options):
    """MIMO continuous-time state space by subspace identification (as `ctid fit --method subspace`): Johansson's
    lambda operator (route='lambda', any sampling) or discrete MOESP + logm (route='discrete'); nx = 0 chooses the
    order from the singular values (r.diagnostics['singular_values']). data: an IdData, or a FrequencyData (an FRF
    matrix, e.g. ctid.frf_from_periodic: McKelvey's frequency-domain subspace method). Options: SubspaceOptions
    (ctid.settings('subspace'))."""
    return _ctid.subspace(data, _options(_ctid.SubspaceOptions, "subspace", {"nx": nx, **options}))


def ssest(data, nx=0, initial=None, **options):
    """MIMO continuous-time state space by output error (as `ctid fit --method ssest`): the subspace start (or
    `initial`, a StateSpace) refined by weighted output error with exact sensitivities; returned in real modal form
    with the parameter covariance, each mode's wn/zeta standard deviation (r.diagnostics['mode_wn_std'],
    ['mode_zeta_std']) and each record's initial state. data: an IdData or a list of them (several records of one
    system). nx = 0: the start's choice; nx_max=B fits nx..B and keeps the least BIC. Options: SsestOptions
    (ctid.settings('ssest')), e.g. estimate_d=False, integrators=1, fixed={'D1_1': 0}; estimate_k=True is the
    prediction-error variant (an innovation gain r.model.K; one-step predictions r.model.predict(data)). data may also be a
    FrequencyData (an FRF matrix, e.g. ctid.frf_from_periodic): weighted least squares from the frequency-domain
    subspace start, weights the data's variances (use_variance=False: estimated from the residuals)."""
    opts = _options(_ctid.SsestOptions, "ssest", {"nx": nx, **options})
    if isinstance(data, FrequencyData):
        return _ctid.ssest(data, initial, opts)
    records = list(data) if isinstance(data, (list, tuple)) else [data]
    return _ctid.ssest(records, initial, opts)


def ssest_crlb(truth, data, noise_variance, **options):
    """The Cramer-Rao bound of ssest's parameters and modes at the true model `truth` for records with these inputs
    and times (at rest) under white output noise of the given variances (one per output); the bound a Monte Carlo
    study compares ssest's spread with (diagnostics mode_wn_std, mode_zeta_std). Options: as ssest."""
    records = list(data) if isinstance(data, (list, tuple)) else [data]
    return _ctid.ssest_crlb(truth, records, noise_variance, _options(_ctid.SsestOptions, "ssest", options))


@_runs("modal")
def modal_fit(data, nb, input=None, **options):
    """El-Shafey (1987) modal-function identification (options: ModalOptions; shifts= is required; input: an
    InputGenerator for a generated input, None for a piecewise-constant one). data: an IdData, or a list of IdData
    with piecewise-constant inputs (several experiments of one system, each from rest, fitted jointly)."""
    return _ctid.modal_fit(data, nb, _modal_options("modal_fit", options), input)


def _modal_options(who, options):
    """windows may be given as ModalWindow objects or (start, length) pairs (seconds); the setting is their flat list."""
    if "windows" in options:
        flat = []
        for w in options["windows"]:
            flat += [w.start, w.length] if isinstance(w, ModalWindow) else list(w) if _np.ndim(w) else [w]
        options["windows"] = flat
    return _options(_ctid.ModalOptions, who, options)


@_runs("modal")
def modal_estimate(data, input, **options):
    """El-Shafey modal parameters p_j and modal-function coefficients q_j (options: ModalOptions; shifts= is
    required). input: the InputGenerator of a generated input, or the sampled input basis (N x n_c; data.u
    for a piecewise-constant input, with windows=piecewise_constant_windows(...))."""
    if not isinstance(input, InputGenerator):
        input = _np.asarray(input, dtype=float).reshape(data.u.shape[0], -1)
    return _ctid.modal_estimate(data, input, _modal_options("modal_estimate", options))


def modal_frequency_response(data, model, period, harmonics, window_start, rule="simpson"):
    """El-Shafey ch. 5: H(j k w_o) at the harmonics k of a periodic input (period in s) from one period
    starting at window_start (>= the largest shift); model: a ModalModel (or result) with p_0."""
    return _ctid.modal_frequency_response(data, getattr(model, "model", model), period, list(harmonics), window_start,
                                          _enum(_ctid.Quadrature, rule, "modal_frequency_response", "rule"))


def modal_step_response(data, model, level_period, horizon):
    """El-Shafey ch. 5: step response on [0, horizon] from a piecewise-constant input whose levels change at
    multiples of level_period; model: p_0 for the shifts i * level_period."""
    return _ctid.modal_step_response(data, getattr(model, "model", model), level_period, horizon)


def modal_impulse_from_step(step, negative_shifts, To, functions=6, rule="simpson"):
    """El-Shafey ch. 5: impulse response from a step response (a TimeResponse) with negative shifts (s)."""
    return _ctid.modal_impulse_from_step(step, _np.asarray(negative_shifts, dtype=float), To, functions,
                                         _enum(_ctid.Quadrature, rule, "modal_impulse_from_step", "rule"))


def prony(y, ts, **options):
    """Prony's method (options: PronyOptions: order, spacing, equations, start)."""
    return _ctid.prony(_np.asarray(y, dtype=float), ts, _options(_ctid.PronyOptions, "prony", options))


@_runs("poles")
def free_response_poles(y, ts, **options):
    """Poles from a free-response data matrix, El-Shafey Theorem 4.3 (options: FreeResponseOptions)."""
    return _ctid.free_response_poles(_np.asarray(y, dtype=float), ts,
                                     _options(_ctid.FreeResponseOptions, "free_response_poles", options))


def modal_response(data, order, kind="step", **options):
    """El-Shafey ch. 5 as one call — what ``ctid response --method modal`` prints: p_0 from the constant-input
    windows, then the step response, the impulse response from it, or the frequency response at the harmonics
    (kind "step", "impulse" or "frequency"). options: ModalResponseOptions (period= required, horizon,
    harmonics, window_start; seconds) and ModalOptions (shifts, basis, windows, ...). Returns a ModalResponse
    (time or frequency, p0, the modal settings used)."""
    _check_names("modal_response", options, list(_ctid.ModalResponseOptions._names) + list(_ctid.ModalOptions._names))
    mine = {k: v for k, v in options.items() if k in _ctid.ModalResponseOptions._names}
    modal = {k: v for k, v in options.items() if k not in mine}
    return _ctid.modal_response(data, order, _enum(_ctid.ResponseKind, kind, "modal_response", "kind"),
                                _options(_ctid.ModalResponseOptions, "modal_response", mine),
                                _options(_ctid.ModalOptions, "modal_response", modal))


@_runs("poles")
def compare_poles(y, ts, order, **options):
    """El-Shafey's data-matrix poles (Theorem 4.3) of a free or generator-forced response beside Prony's — what
    ``ctid poles`` prints (options: PolesOptions, seconds; ``shifts`` required, one per pole of the system and of the
    generator). Returns a PolesComparison (data_matrix, prony or None with prony_problem, the settings used)."""
    return _ctid.compare_poles(_np.asarray(y, dtype=float).ravel(), ts, order,
                               _options(_ctid.PolesOptions, "poles", options))


@_runs("physical")
def fit_physical_step(model, parameters, compressed, data=None, **options):
    """Gawthrop & Wang stage 2 against the FSF step response. parameters: {"name": initial} or
    {"name": {"initial": .., "lower": .., "upper": .., "fixed": ..}} (options: PhysicalFitOptions). data: the record
    the compressed model was fitted to; with it, fit is the simulation fit on the record (else none is computed);
    diagnostics.scalars["compressed_fit_percent"] is the match to the compressed response."""
    return _ctid.fit_physical_step(model, parameters, getattr(compressed, "model", compressed),
                                   _options(_ctid.PhysicalFitOptions, "fit_physical_step", options), data)


@_runs("physical")
def fit_physical_frequency(model, parameters, compressed, data=None, **options):
    """Gawthrop & Wang stage 2 against the FSF frequency samples (GW 30); data and fit as fit_physical_step."""
    return _ctid.fit_physical_frequency(model, parameters, getattr(compressed, "model", compressed),
                                        _options(_ctid.PhysicalFitOptions, "fit_physical_frequency", options), data)


@_runs("physical")
def fit_physical_raw(model, parameters, data, a=0.0, **options):
    """Physical parameters by output error on the raw record (exponentially windowed when a > 0). data: an IdData or
    a list of IdData (several experiments: their output errors stacked, one parameter set)."""
    return _ctid.fit_physical_raw(model, parameters, data, a,
                                  _options(_ctid.PhysicalFitOptions, "fit_physical_raw", options))


def rls_svf_recursive(nb, nf, **options):
    """Johansson (1986) recursive least squares on filtered signals: an RlsSvf to feed with update() or run()
    sample by sample (options: RlsSvfOptions: tau, forgetting, alpha, fixed, ...). ctid.rls_svf(data, ..) runs it
    once over a record and returns the usual result."""
    return _ctid.RlsSvf(nb, nf, _options(_ctid.RlsSvfOptions, "rls_svf", options))


def _document_settings():
    """Appends to each function's docstring the keyword options of the registered method it runs (its own name, or
    the one _runs declares) with kind, unit, range and default — read from the library's option table (the same
    names and defaults as ``ctid fit --method M --help`` and ``--set``)."""
    registered = set(methods())
    for f in list(globals().values()):
        if not callable(f) or getattr(f, "__module__", None) != __name__ or f.__name__.startswith("_"):
            continue
        method = getattr(f, "_method", f.__name__)
        if method not in registered:
            continue
        lines = ["", "", f"Keyword options (ctid.settings({method!r}); the CLI's --set NAME=VALUE):"]
        for s in settings(method):
            unit = f" {s['unit']}" if s["unit"] else ""
            rng = f", {s['range']}" if s["range"] else ""
            lines.append(f"    {s['name']} = {s['default'] or '(none)'}{unit} -- {s['doc']} ({s['kind']}{rng})")
        f.__doc__ = (f.__doc__ or "").rstrip() + "\n".join(lines) + "\n"


_document_settings()
