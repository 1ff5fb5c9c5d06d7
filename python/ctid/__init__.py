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


def _html_pre(self):
    """Notebooks: the repr in a monospaced block (escaped)."""
    import html
    return "<pre>" + html.escape(repr(self)) + "</pre>"


# Notebooks show every class's repr in a monospaced block: generated for each class of the module (results carry
# their own, the library's brief_text, bound in C++).
for _cls in list(vars(_ctid).values()):
    if isinstance(_cls, type) and not issubclass(_cls, BaseException) and "_repr_html_" not in vars(_cls):
        _cls._repr_html_ = _html_pre


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


# ---- estimators and tools with keyword options (ctid/_methods.py) ----

from ._methods import _options  # noqa: E402,F401  (keyword options -> options struct, for ctid.batch and tests)
from ._methods import (  # noqa: E402,F401  (re-exported)
    lssvf, ivsvf, srivc, srivc_auto, oe, tfest, rls_svf, srivc_miso, srivc_closed_loop, tf_from_frequency,
    select_order, fsf, fsf_from_spectra, frols, narmax, narx, kia_linear, kia_quadratic, kia_cubic, kia, nde_oe,
    greybox_model, greybox, subspace, ssest, ssest_crlb, modal_fit, modal_estimate, modal_frequency_response,
    modal_step_response, modal_impulse_from_step, prony, free_response_poles, modal_response, compare_poles,
    fit_physical_step, fit_physical_frequency, fit_physical_raw, rls_svf_recursive,
)


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


from . import batch  # noqa: E402,F401  (ctid.batch.fit_many; imports Dask only when called)
