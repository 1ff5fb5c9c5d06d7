"""ctid — continuous-time system identification.

The C++ library (module ``ctid._ctid``) with keyword arguments: every estimator takes the data, the
structure, and the fields of its C++ options struct as keyword arguments with the same names, e.g.
``ctid.srivc(data, nb=2, nf=2, max_iterations=50)``. Results carry ``.model``, ``.parameters``
(names, values, std, covariance), ``.fit``, ``.summary`` and ``.diagnostics``; ``repr(result)`` is a
brief report. Bad input raises ``ctid.InvalidArgument`` / ``ctid.InvalidOptions`` (ValueErrors) or
``ctid.FileError`` (an OSError); an estimator that does not succeed returns a result whose
``summary.termination`` says why and ``usable()`` is False. Ctrl-C stops a long estimation: the
result comes back with termination ``"interrupted"``.
"""
import difflib as _difflib

import numpy as _np

from . import _ctid
from ._ctid import (  # noqa: F401  (re-exported)
    CorrelationTest, DeadbeatObserver, average_periods, frf_from_periodic, FileError, FrequencyData, FsfModel, GreyboxModel, GreyboxSimulation, IdData, InputGenerator, InvalidArgument,
    InvalidOptions, MisoModel, ModalModel, ModalParameters, ModalWindow, modal_parameters, NarxModel, NarxTerm, NdeModel, NdeSimulation, NdeTerm,
    NonlinearCorrelationTests, PhysicalModel, ResultFile, Simulation, StateSpace, TransferFunction, add_noise_snr, crlb, fit_percent, frequency_grid,
    example_data, example_data_names, generator_fitted_to_input, html_report, kia_product_candidates,
    input_residual_crosscorrelation, load, magnitude_band, response_band, drawn_models, compare_models,
    html_comparison_report, ModelComparison, mode_uncertainty, frequency_response_std, methods, settings, diagnostics, fit_methods, method_capabilities, narx_candidates, narx_noise_candidates,
    nonlinear_correlation_tests, one_sided_dft, piecewise_constant_windows, prbs, random_binary, multisine, steps, white_noise, read_narx_json, read_nde_json,
    greybox_initial_state, read_result, residual_autocorrelation, response_horizon, time_grid, write_result,
    svf_gamma, svf_information, SvfInformation, RstController, simulate_closed_loop,
)

__version__ = _ctid.__version__


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


def _columns(a, name):
    a = _np.asarray(a)
    if _np.iscomplexobj(a):
        raise InvalidArgument(f"IdData.from_arrays: {name} is complex ({a.dtype}); give real signals (e.g. the real part "
                              "and the imaginary part as two channels)")
    if a.dtype.kind in "mM":
        raise InvalidArgument(f"IdData.from_arrays: {name} holds {a.dtype} values (dates or durations); give numbers")
    a = a.astype(float)
    if a.ndim == 1:
        a = a.reshape(-1, 1)
    if a.ndim != 2:
        raise InvalidArgument(f"IdData.from_arrays: {name} must be 1-D or (n_samples, n_channels) (got shape {a.shape})")
    return a


def _from_arrays(cls, u, y, ts=None, t=None, t0=0.0, input_names=None, output_names=None, intersample=None):
    """A record from arrays shaped (n_samples,) or (n_samples, n_channels): uniform with ts (and t0), or at the
    strictly increasing times t (uniform when every time is within 1e-3 Ts of a uniform grid, as in ctid.load;
    the distance is data.uniform_time_deviation).
    u may be None or empty for a time series."""
    y = _columns(y, "y")
    u = _np.zeros((y.shape[0], 0)) if u is None else _columns(u, "u")
    if (ts is None) == (t is None):
        raise InvalidArgument("IdData.from_arrays: give either ts (uniform sampling) or t (sample times)")
    d = IdData(u, y, float(ts), float(t0)) if t is None else IdData.from_times(u, y, _seconds(t, "t"))
    if input_names is not None:
        d.input_names = list(input_names)
    if output_names is not None:
        d.output_names = list(output_names)
    if intersample is not None:
        d.intersample = intersample
    return d


def _seconds(t, name):
    """Sample times in seconds: numbers as they are; numpy/pandas timedelta or datetime values converted from their
    unit (datetimes relative to the first sample), never read as raw nanosecond counts. Complex values are refused."""
    a = _np.asarray(t)
    if a.dtype.kind == "M":
        a = a - a.ravel()[0]
    if a.dtype.kind == "m":
        return (a / _np.timedelta64(1, "ns")).astype(float).ravel() * 1e-9
    if _np.iscomplexobj(a):
        raise InvalidArgument(f"IdData.from_arrays: {name} is complex; sample times are real seconds")
    return a.astype(float).ravel()


def _from_pandas(cls, frame, inputs, outputs, ts=None, time=None, intersample=None):
    """A record from the columns of a pandas DataFrame (time: a column of sample times in seconds, or of
    timedelta / datetime values, converted to seconds; or ts)."""
    t = None if time is None else _seconds(frame[time].to_numpy(), time)
    return _from_arrays(cls, frame[list(inputs)].to_numpy() if inputs else None,
                        frame[list(outputs)].to_numpy(), ts=ts, t=t,
                        input_names=inputs, output_names=outputs, intersample=intersample)


IdData.from_arrays = classmethod(_from_arrays)
IdData.from_pandas = classmethod(_from_pandas)


def _iddata_getitem(self, key):
    """d[a:b]: the samples a..b-1 as an IdData (step 1; negative indices count from the end), IdData.slice with Python's
    rules. d[k]: sample k as (t, u, y) with u and y arrays of the channels."""
    if isinstance(key, (int, _np.integer)):
        n = len(self)
        k = int(key) + n if key < 0 else int(key)
        if not 0 <= k < n:
            raise IndexError(f"IdData index {key} is outside the {n} samples")
        return float(self.times[k]), self.u[k, :].copy(), self.y[k, :].copy()
    if not isinstance(key, slice):
        raise TypeError(f"IdData indices are sample numbers or slices, e.g. d[100:500] (got {type(key).__name__})")
    begin, end, step = key.indices(len(self))
    if step != 1:
        raise InvalidArgument(f"IdData[{key.start}:{key.stop}:{key.step}]: only consecutive samples (step 1); "
                              "resample the signals and build a new IdData for another rate")
    return self.slice(begin, max(begin, end))


def _iddata_to_pandas(self):
    """A pandas DataFrame with a column t (s) and one column per input and output, named as the channels."""
    import pandas as pd
    cols = {"t": self.times}
    for i, n in enumerate(self.input_names):
        cols[n] = self.u[:, i]
    for j, n in enumerate(self.output_names):
        cols[n if n not in cols else f"{n} (output)"] = self.y[:, j]
    return pd.DataFrame(cols)


def _iddata_repr(self):
    sampling = f"Ts={self.ts:g} s" if self.is_uniform else "irregular times"
    t = self.times
    return (f"IdData({len(self)} samples, {sampling}, {t[-1] - t[0]:g} s; inputs {list(self.input_names)}, "
            f"outputs {list(self.output_names)})")


IdData.__getitem__ = _iddata_getitem
IdData.to_pandas = _iddata_to_pandas
IdData.__repr__ = _iddata_repr


def _tf_to_scipy(self):
    """This transfer function as scipy.signal.TransferFunction (continuous time). A delay has no place in that
    class: a model with one is refused (scipy would silently drop it)."""
    import scipy.signal
    if self.delay != 0:
        raise InvalidArgument(f"TransferFunction.to_scipy: the model has a delay of {self.delay:g} s, which "
                              "scipy.signal.TransferFunction cannot hold; use a Pade approximation or keep the delay apart")
    return scipy.signal.TransferFunction(_np.asarray(self.num), _np.asarray(self.den))


def _tf_from_scipy(cls, system, delay=0.0):
    """A TransferFunction from a continuous-time scipy.signal LTI object (TransferFunction, ZerosPolesGain or
    StateSpace; single input and output); delay in seconds."""
    import scipy.signal
    if getattr(system, "dt", None) not in (None,):
        raise InvalidArgument(f"TransferFunction.from_scipy: the system is discrete-time (dt = {system.dt}); ctid's "
                              "models are continuous-time")
    tf = system.to_tf() if hasattr(system, "to_tf") else scipy.signal.TransferFunction(system)
    num = _np.atleast_2d(tf.num)
    if num.shape[0] != 1:
        raise InvalidArgument(f"TransferFunction.from_scipy: {num.shape[0]} outputs; give a single-output system")
    return cls(_np.trim_zeros(num[0], "f") if _np.any(num[0]) else [0.0], _np.asarray(tf.den, dtype=float), delay)


TransferFunction.to_scipy = _tf_to_scipy
TransferFunction.from_scipy = classmethod(_tf_from_scipy)


def _parameters_repr(p):
    rows = [f"{'parameter':<16}{'value':>14}{'std':>12}"]
    for i, name in enumerate(p.names):
        sd = "fixed" if p.fixed and p.fixed[i] else f"{p.std[i]:.4g}" if len(p.std) else "-"
        rows.append(f"{name:<16}{p.values[i]:>14.6g}{sd:>12}")
    return "\n".join(rows)


def _fit_repr(f):
    return (f"FitReport(fit {_ctid.fit_percent_text(f.fit_percent)} %, nrmse {f.nrmse:.4g}, mse {f.mse:.4g}, "
            f"aic {f.aic:.6g}, bic {f.bic:.6g}, {f.n_samples} samples)")


def _summary_repr(s):
    return (f"Summary({s.termination}, {s.iterations} iteration(s), {s.seconds:.3g} s"
            + (f": {s.message}" if s.message else "") + ")")


def _diagnostics_repr(g):
    lines = [f"Diagnostics(condition number {g.condition_number:.3g})"]
    lines += [f"  {k} = {v:.6g}" for k, v in g.scalars.items()]
    lines += [f"  {k} = [{', '.join(f'{x:.4g}' for x in v[:8])}{', ...' if len(v) > 8 else ''}]"
              for k, v in g.vectors.items()]
    lines += [f"  chosen: {c}" for c in g.choices] + [f"  warning: {w}" for w in g.warnings]
    return "\n".join(lines)


def _html_pre(self):
    """Notebooks: the repr in a monospaced block (escaped)."""
    import html
    return "<pre>" + html.escape(repr(self)) + "</pre>"


_ctid.ParameterSet.__repr__ = _parameters_repr
_ctid.FitReport.__repr__ = _fit_repr
_ctid.Summary.__repr__ = _summary_repr
_ctid.Diagnostics.__repr__ = _diagnostics_repr
# Results print their library text (brief_text) in repr() and notebooks, every result class alike (bound in C++).
for _cls in (IdData, _ctid.ParameterSet, _ctid.FitReport, _ctid.Summary, _ctid.Diagnostics, TransferFunction,
             StateSpace, MisoModel, FsfModel, NarxModel, NdeModel, GreyboxModel):
    _cls._repr_html_ = _html_pre


# ---- responses of the models that have no closed form in C++ ----

def _miso_columns(method):
    def f(self, x):
        """One column per input channel."""
        return _np.column_stack([getattr(g, method)(_np.asarray(x, dtype=float)) for g in self.channels])
    f.__name__ = method
    return f


MisoModel.freqresp = _miso_columns("freqresp")
MisoModel.step = _miso_columns("step")
MisoModel.impulse = _miso_columns("impulse")


def _nde_freqresp(self, w):
    """The linear part's frequency response H_1(jw) (w in rad/s)."""
    return _np.array([self.h1(1j * x) for x in _np.atleast_1d(_np.asarray(w, dtype=float))])


def _nde_step(self, t, amplitude=1.0):
    """Response from rest to the step amplitude * 1(t) (amplitude matters: the model is nonlinear);
    ctid.step_response on times from t[0]."""
    t = _np.asarray(t, dtype=float)
    return step_response(self, t - t[0], amplitude)


def _narx_freqresp(self, w, zoh=True):
    """The linear part's frequency response H_1(jw) read as continuous-time (zoh: hold factor removed)."""
    return _np.array([self.gfrf([1j * x], zoh) for x in _np.atleast_1d(_np.asarray(w, dtype=float))])


def _narx_step(self, t, amplitude=1.0):
    """Free-run response from rest to the step amplitude * 1(t); t on the model's grid k * ts (ctid.step_response
    on times from t[0])."""
    t = _np.asarray(t, dtype=float)
    return step_response(self, t - t[0], amplitude)


NdeModel.freqresp, NdeModel.step = _nde_freqresp, _nde_step
NarxModel.freqresp, NarxModel.step = _narx_freqresp, _narx_step


# ---- one entry point for every fit of records (the library's registry) ----

def _fit(data, method=None, *, nb=None, nf=None, nk=0, orders=None, model=None, parameters=None, route="fsf",
         initial=None, narx=None, reference=None, **settings):
    """ctid.fit's work: (typed result, the registry name of the method that ran, its settings as (name, text))."""
    if orders is None and (nb is not None or nf is not None):
        if nf is None:
            raise TypeError("fit: nb needs nf (the model order)")
        orders = [(nf if nb is None else nb, nf, nk)]
    elif orders is not None:
        orders = [tuple(orders)] if len(orders) == 3 and all(isinstance(x, int) for x in orders) else \
            [tuple(o) for o in orders]
    orders = orders or []
    if method is None:
        method = _ctid.default_method(bool(orders), isinstance(data, FrequencyData))
    if not isinstance(method, str):
        raise TypeError(f"fit: method must be a method's name (ctid.fit_methods() lists them), got {method!r}")
    if isinstance(data, (list, tuple)):
        data = list(data)
    caps = _ctid.method_capabilities(method)
    greybox_, expression = None, None
    if model is not None:
        if caps["greybox_model"]:
            greybox_ = greybox_model(model)
        elif caps["physical_model"]:
            expression = str(model)
        else:
            raise TypeError(f"fit: {method} takes no model (greybox and physical do)")
    references = []
    if reference is not None:
        refs = reference if isinstance(reference, (list, tuple)) else [reference]
        references = [_np.asarray(r, dtype=float) for r in refs]
    return _ctid.fit(method, data, orders, settings, initial, greybox_, expression, parameters or {}, route,
                     references, narx)


def fit(data, method=None, **kwargs):
    """Fit a model to records by any registered method, by its name: the library's registry runs it, as
    ``ctid fit --method`` does (ctid.fit_methods() lists the names, ctid.method_capabilities(name) what each takes,
    ctid.settings(name) its settings). data: an IdData, a list of IdData (several experiments of one system, fitted
    jointly) or a FrequencyData. method: default srivc when orders are given, srivc_auto otherwise.

    Structure keywords: nb, nf, nk (nb defaults to nf) or orders=[(nb, nf, nk), ...] one per input; model= the
    grey-box model (dict, file or GreyboxModel) or the physical expression ("k1/(s^2 - k2)") with parameters=
    {"k1": 1, ...} and route= fsf | frequency | raw; initial= a StateSpace (ssest); narx= a NarxModel (kia);
    reference= one reference per record (srivc in closed loop; its controller is the setting controller=).
    Every other keyword is a setting of the method, by the names of ctid.settings(method).

    Returns the typed result (TransferFunctionResult, MisoResult, StateSpaceResult, ...)."""
    return _fit(data, method, **kwargs)[0]


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


def compare_poles(y, ts, order, **options):
    """El-Shafey's data-matrix poles (Theorem 4.3) of a free or generator-forced response beside Prony's — what
    ``ctid poles`` prints (options: PolesOptions, seconds; ``shifts`` required, one per pole of the system and of the
    generator). Returns a PolesComparison (data_matrix, prony or None with prony_problem, the settings used)."""
    return _ctid.compare_poles(_np.asarray(y, dtype=float).ravel(), ts, order,
                               _options(_ctid.PolesOptions, "poles", options))


def fit_physical_step(model, parameters, compressed, data=None, **options):
    """Gawthrop & Wang stage 2 against the FSF step response. parameters: {"name": initial} or
    {"name": {"initial": .., "lower": .., "upper": .., "fixed": ..}} (options: PhysicalFitOptions). data: the record
    the compressed model was fitted to; with it, fit is the simulation fit on the record (else none is computed);
    diagnostics.scalars["compressed_fit_percent"] is the match to the compressed response."""
    return _ctid.fit_physical_step(model, parameters, getattr(compressed, "model", compressed),
                                   _options(_ctid.PhysicalFitOptions, "fit_physical_step", options), data)


def fit_physical_frequency(model, parameters, compressed, data=None, **options):
    """Gawthrop & Wang stage 2 against the FSF frequency samples (GW 30); data and fit as fit_physical_step."""
    return _ctid.fit_physical_frequency(model, parameters, getattr(compressed, "model", compressed),
                                        _options(_ctid.PhysicalFitOptions, "fit_physical_frequency", options), data)


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


# ---- simulation of any model on a record ----

def _one_column(a):
    return a[:, 0] if a.shape[1] == 1 else a


def step_response(model, t, amplitude=1.0):
    """Response from rest of any model (or result) to the step amplitude * 1(t) at the times t (s) — the
    library's model_step_response, which the report plots: one column per input (1-D for one input). Linear
    models exactly; NARX/NDE models simulated (for a nonlinear model the amplitude matters)."""
    return _one_column(_ctid.model_step_response(getattr(model, "model", model), _np.asarray(t, dtype=float),
                                                 float(amplitude)))


def impulse_response(model, t):
    """Impulse response of a linear model (or result) at the times t (s); one column per input (1-D for one)."""
    return _one_column(_ctid.model_impulse_response(getattr(model, "model", model), _np.asarray(t, dtype=float)))


def frequency_response(model, w):
    """G(jw) of a linear model (or result) at w (rad/s), with its delay; one column per input (1-D for one)."""
    return _one_column(_ctid.model_frequency_response(getattr(model, "model", model), _np.asarray(w, dtype=float)))


def simulate(model, data, initial=None, x0=None, initial_samples=0):
    """Simulated output of any model (or result) driven by the inputs of `data` — the library's one
    simulate() (the CLI's simulate, validate and report use it too). initial: "rest" (zero state),
    "measured" (NARX: the first measured outputs; NDE: y(0)) or "estimated" (linear models: the
    least-squares initial state on `data`; NARX: the measured history; NDE and grey box: x0, by default the x0 an
    output-error fit estimated; grey box with initial_samples=N: the state from the record's first N samples
    only); None: for a result, the library's default for a free run (as ``ctid simulate``: rest, a grey-box model
    from its fit's initial state), for a bare model rest. Returns a 1-D array for a single-output model (N x ny
    otherwise); a simulation that stops being finite warns with the reason and returns NaN from there."""
    if hasattr(model, "diagnostics") and x0 is None:
        s = _ctid.simulate_result(model, data, "free_run", initial or "", int(initial_samples))
    else:
        s = _ctid.simulate_model(getattr(model, "model", model), data, initial or "rest",
                                 _np.zeros(0) if x0 is None else _np.asarray(x0, dtype=float), int(initial_samples))
    if not s.ok():
        import warnings
        warnings.warn(s.problem, RuntimeWarning, stacklevel=2)
    return s.y[:, 0] if s.y.shape[1] == 1 else s.y


def compare(data, models, initial=None, max_lag=25, report=None, title=""):
    """Several models on one record side by side — the library's compare_models (``ctid compare`` uses it).

    models: a dict {name: model}, or a list of models, results, result-file paths or (name, model) pairs (unnamed
    ones are called by their file path or "model 1", "model 2", ..). Each is simulated on ``data`` from ``initial``
    ("rest", "measured", "estimated"; None = each model's validation condition: estimated for linear and grey-box
    models, measured for NARX/NDE, rest for FSF) and scored: fits (one FitReport per output), whiteness and
    independence (residual tests, ``max_lag`` lags). A model that diverges is kept, with ``simulation.problem``.
    report: a path to write the side-by-side HTML report to (fits, overlaid simulations, Bode, step, poles).
    Returns the list of ModelComparison, in the given order."""
    items = list(models.items()) if isinstance(models, dict) else list(models)
    named = []
    for k, m in enumerate(items):
        name = None
        if isinstance(m, tuple) and len(m) == 2 and isinstance(m[0], str):
            name, m = m
        if isinstance(m, str):
            name, m = name or m, _ctid.read_result(m).result
        named.append((name or "model %d" % (k + 1), getattr(m, "model", m)))
    out = _ctid.compare_models(data, named, initial or "", int(max_lag))
    if report is not None:
        _ctid.html_comparison_report(data, out, str(report), title)
    return out


# Python functions of the registered methods whose name differs from the method's.
_METHOD_FUNCTIONS = {"physical": ["fit_physical_step", "fit_physical_frequency", "fit_physical_raw"],
                     "modal": ["modal_fit", "modal_estimate"], "poles": ["free_response_poles", "compare_poles"]}


def _document_options():
    """Appends to each method function's docstring its keyword options with kind, unit, range and default — read from
    the library's option table (the same names and defaults as ``ctid fit --method M --help`` and ``--set``)."""
    for method in methods():
        for name in _METHOD_FUNCTIONS.get(method, [method]):
            f = globals().get(name)
            if not callable(f) or getattr(f, "__module__", None) != __name__:
                continue
            lines = ["", "", f"Keyword options (ctid.settings({method!r}); the CLI's --set NAME=VALUE):"]
            for s in settings(method):
                unit = f" {s['unit']}" if s["unit"] else ""
                rng = f", {s['range']}" if s["range"] else ""
                lines.append(f"    {s['name']} = {s['default'] or '(none)'}{unit} -- {s['doc']} ({s['kind']}{rng})")
            f.__doc__ = (f.__doc__ or "").rstrip() + "\n".join(lines) + "\n"


_document_options()

from . import batch  # noqa: E402,F401  (ctid.batch.fit_many; imports Dask only when called)
