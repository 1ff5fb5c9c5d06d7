"""ctid.batch — one identification method over many records, on threads or a Dask cluster.

``fit_many(records, method=None, client=None, **options)`` fits every record with ``ctid.fit(record, method,
**options)`` (the library's registry: the method's name, its structure keywords and settings) (``fit_many(paths, method="srivc", nb=1, nf=1)`` is
``ctid.srivc(data, nb=1, nf=1)`` per record) and returns a pandas DataFrame, one row per record. It runs on the
``dask.distributed`` client given (a cluster of several machines unchanged), or with ``client=None`` on a pool of
threads in this process (the fits release the GIL, so threads use every core without copying the records). A record that cannot be read or fitted, or whose fit is not usable, is a row with its error; a task lost
with its worker is run again by Dask (``retries``) and every record gives exactly one row. With ``out=`` the rows
are also written to a CSV or JSON-lines file as they arrive, so that ``resume=True`` continues an interrupted batch
with only the records not yet written.

``monte_carlo(model, u, ts, runs=, snr_db=/noise_std=, seed=, methods=, **options)`` runs a Monte Carlo study of
estimators on the same executors: only the model, the input and the seeds travel, each worker draws its runs' noise
from their seeds, and the summary gives bias, std and std over the Cramer-Rao bound per method and parameter.
"""
import os as _os
import sys as _sys
import time as _time

from . import _ctid

#: The columns every row has, in this order; then, per parameter NAME of the model, NAME and NAME_std (the library's
#: batch rows, which ctid batch writes too).
COLUMNS = list(_ctid.BATCH_COLUMNS)


def _row(rid, method, result=None, error="", seconds=0.0):
    """The library's batch row (io/batch_file.hpp): the columns of COLUMNS, then NAME and NAME_std per parameter."""
    import ctid
    if result is None:
        return ctid._ctid.batch_row(rid, method, None, error, seconds)
    return ctid._ctid.batch_row(rid, method, result)


def fit_one(rid, record, method, options, file_options):
    """One row: the record (an IdData or a file path) read and fitted by ctid.fit(record, method, **options). Every
    failure is the row's error, never an exception (Dask would retry a task that raises)."""
    import ctid
    t0 = _time.perf_counter()
    try:
        if not isinstance(record, ctid.IdData):
            fo = dict(file_options)
            if "inputs" not in fo or "outputs" not in fo:
                raise ctid.InvalidArgument("fit_many: a record given as a file needs inputs= and outputs= (column "
                                           "names or 1-based numbers)")
            fo["inputs"] = [str(c) for c in _as_list(fo["inputs"])]
            fo["outputs"] = [str(c) for c in _as_list(fo["outputs"])]
            record = ctid.load(_os.fspath(record), **fo)
        result, ran, _ = ctid._fit(record, method, **options)
        return _row(rid, ran, result)
    except Exception as e:  # noqa: BLE001 -- every failure becomes the row's error
        return _row(rid, method, error=f"{type(e).__name__}: {e}", seconds=_time.perf_counter() - t0)


def fit_chunk(items, method, options, file_options):
    """fit_one over several (id, record) pairs: one Dask task (a task costs milliseconds of scheduling, as much as
    a fit of a few thousand samples)."""
    return [fit_one(rid, rec, method, options, file_options) for rid, rec in items]


def _as_list(x):
    return list(x) if isinstance(x, (list, tuple)) else [x]


def _records(records):
    """(id, record) pairs: paths are their own ids, IdData objects their position, pairs as given."""
    import ctid
    out = []
    for i, r in enumerate(records):
        if isinstance(r, tuple) and len(r) == 2:
            out.append((str(r[0]), r[1]))
        elif isinstance(r, ctid.IdData):
            out.append((str(i), r))
        elif isinstance(r, (str, _os.PathLike)):
            out.append((_os.fspath(r), _os.fspath(r)))
        else:
            raise TypeError(f"fit_many: record {i} is a {type(r).__name__}; give file paths, IdData objects or "
                            f"(id, IdData) pairs")
    ids = [rid for rid, _ in out]
    if len(set(ids)) != len(ids):
        dup = sorted({x for x in ids if ids.count(x) > 1})[:3]
        raise ValueError(f"fit_many: record ids must be unique; repeated: {', '.join(dup)}")
    return out


def _writer(out, resume):
    """The library's rows file (BatchFile: CSV or JSON lines, written row by row), never replacing a file unless
    resuming it."""
    import ctid
    path = _os.fspath(out)
    if _os.path.exists(path) and not resume:
        raise FileExistsError(f"ctid.batch: {path} exists; resume=True continues it (only the rows not in it are "
                              f"fitted), or remove it")
    return ctid._ctid.BatchFile(path, resume)


def _show(label, done, total, errors, final=False):
    _sys.stderr.write(f"\r{label}: {done}/{total} done, {errors} with an error" + ("\n" if final else ""))
    _sys.stderr.flush()


def _check_jobs(who, jobs):
    """ValueError for a thread count that is not a whole number >= 1 (None: every core)."""
    if jobs is not None and (isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1):
        raise ValueError(f"{who}: jobs must be a whole number >= 1 (got {jobs!r}); None uses every core")


def _threads(client, jobs):
    """Threads the work runs on: `jobs` (default every core) locally, the cluster's worker threads on Dask."""
    if client is None:
        return jobs or _os.cpu_count() or 1
    return max(1, sum(client.nthreads().values()))


#: At most this many records (or Monte Carlo runs) per task, and at most this many bytes of records held in memory:
#: a task's rows reach the output file, the progress line and a resumed batch when the task ends.
CHUNK_MAX, CHUNK_BYTES = 256, 16 << 20


def _chunk_size(n, threads, record_bytes=0):
    """Items per task: 8 tasks per thread (the load stays balanced), at most CHUNK_MAX items and CHUNK_BYTES of
    records in memory. A Dask task costs about 8 ms of CPU in the client and the worker processes together (measured
    on 2 cores, docs/scale.md): with at most 32 records of 10 000 samples per task 15-16 % of the CPU went beside the
    fits, with 8 tasks per thread 9-11 %."""
    size = min(CHUNK_MAX, -(-n // (8 * threads)))
    if record_bytes:
        size = min(size, CHUNK_BYTES // record_bytes)
    return max(1, size)


def _execute(func, tasks, client, jobs, retries, rows, writer, progress, done, total, label):
    """Runs func(*args) for every args of `tasks` (each returns a list of rows) on a thread pool (client None) or
    the Dask client; every row goes into `rows` (by id), the writer and the progress display as its task ends."""
    import concurrent.futures as cf

    errors = sum(1 for r in rows.values() if r.get("error"))
    # The local default is a pool of threads in this process (the standard library's executor: the fits release
    # the GIL, and nothing is copied); a Dask client gets the same tasks as futures with retries.
    pool = cf.ThreadPoolExecutor(max_workers=_threads(None, jobs)) if client is None else None
    try:
        if pool:
            futures = [pool.submit(func, *args) for args in tasks]
            as_completed = cf.as_completed
        else:
            from distributed import as_completed
            stamp = _time.time_ns()
            futures = [client.submit(func, *args, retries=retries, key=f"ctid-{label}-{stamp}-{i}", pure=False)
                       for i, args in enumerate(tasks)]
        last = 0.0
        for fut in as_completed(futures):
            task_rows = fut.result()
            if not pool:
                fut.release()
            for row in task_rows:
                rows[str(row["id"])] = row
                if writer:
                    writer.add(row)
                done += 1
                errors += bool(row["error"])
                if callable(progress):
                    progress(done, total)
            if progress is True and (_time.monotonic() - last > 0.5 or done == total):
                last = _time.monotonic()
                _show(label, done, total, errors, final=done == total)
    finally:
        if pool:
            pool.shutdown(cancel_futures=True)


#: The Dask settings of local_cluster (see there).
LEAN_DASK_CONFIG = {"distributed.worker.profile.enabled": False, "distributed.admin.tick.interval": "500ms"}


def local_cluster(workers=None, **kwargs):
    """A dask.distributed LocalCluster for batches of ctid fits on this machine: `workers` worker processes (default:
    every core) of one thread each, with Dask's statistical profiler off and its event-loop health check every
    500 ms instead of 20 ms. The profiler samples the stack of every worker thread every 10 ms to profile Python
    code; a ctid fit is C++ and releases the GIL, so it sees nothing and only takes CPU from the fits. With a worker
    per core those wake-ups take the fits' cores: on 2 cores the two settings cut the CPU used beside the fits from
    9-11 % to 5-6 % (docs/scale.md). The settings also hold for the workers the nannies restart. kwargs go to
    LocalCluster (e.g. dashboard_address=":0"; a config= dict for the workers is merged over the settings). Give the
    cluster to dask.distributed.Client, and the client to fit_many or monte_carlo. Workers started on other machines
    get the same settings from the environment: DASK_DISTRIBUTED__WORKER__PROFILE__ENABLED=False and
    DASK_DISTRIBUTED__ADMIN__TICK__INTERVAL=500ms."""
    import dask
    import distributed

    if workers is not None and (isinstance(workers, bool) or not (isinstance(workers, int) and workers >= 1)):
        raise ValueError(f"local_cluster: workers must be a whole number >= 1 (got {workers!r})")
    kwargs.setdefault("threads_per_worker", 1)
    kwargs.setdefault("processes", True)
    with dask.config.set(LEAN_DASK_CONFIG):
        # The scheduler and the nannies read the settings now; each nanny also passes its own copy of the whole
        # configuration to every worker process it starts, restarts included (without a deep copy of its own it
        # would share Dask's global one, from which the settings are gone after this block).
        whole = dask.config.merge(dask.config.config, kwargs.pop("config", {}))
        return distributed.LocalCluster(n_workers=workers or _os.cpu_count() or 1, config=whole, **kwargs)


def _check_method(who, method, options):
    """The registry name of `method` (None: ctid fit's default for these options); ValueError for a name that is not
    a fit of records."""
    import ctid
    if method is None:
        return ctid._ctid.default_method(any(k in options for k in ("nb", "nf", "orders")))
    try:
        caps = ctid.method_capabilities(method) if isinstance(method, str) else None
    except ctid.InvalidOptions:
        caps = None
    if caps is None or not caps["records"]:
        raise ValueError(f"{who}: '{method}' is not an estimator of ctid (ctid.fit_methods() lists them)")
    return method


def fit_many(records, method=None, client=None, *, out=None, resume=False, progress=True, retries=2, jobs=None,
             chunk=None,
             inputs=None, outputs=None, time=None, ts=None, intersample=None, **options):
    """Fit every record with ``ctid.fit(record, method, **options)``; a pandas DataFrame, one row per record.

    records: file paths (read by ctid.load with inputs=, outputs= and time=/ts=/intersample=), IdData objects (id =
    position) or (id, IdData) pairs. method: the name of a fit of the registry (ctid.fit_methods(): "srivc",
    "srivc_auto", "oe", "tfest", "ssest", "fsf", "greybox", ...); None: ctid fit's default, srivc with orders
    (nb=, nf=) and srivc_auto without; options: ctid.fit's keywords, as for one record. The rows' method is the
    registry name of the method that ran.
    client: a dask.distributed.Client (its cluster runs the fits: records and options are sent to the workers, the
    library is not); None: a pool of ``jobs`` threads (default: every core) in this process.
    out: a .csv or .jsonl file the rows are written to as they arrive; resume=True continues a batch that stopped
    (the records whose id is in `out` are not fitted again; without resume an existing file is an error, never
    overwritten). progress: True prints a line on stderr, a callable gets (done, total) after each row.
    retries: how often Dask runs a task again whose worker was lost. chunk: records per Dask task (default: 8 tasks
    per worker thread, at most CHUNK_MAX records and CHUNK_BYTES of records in memory each, so that the scheduling of
    a task, about 8 ms of CPU, is small beside its fits while the load stays balanced).

    Columns: id, method, model (its type), orders, fit_percent, termination, usable, seconds, error ('' for a usable
    fit; the exception, or why the fit is not usable), then NAME and NAME_std for each parameter. Rows are in the
    order of `records`.
    """
    import pandas as pd
    import ctid

    method = _check_method("fit_many", method, options)
    _check_jobs("fit_many", jobs)
    if chunk is not None and not (isinstance(chunk, int) and chunk >= 1):
        raise ValueError(f"fit_many: chunk must be a whole number >= 1 (got {chunk!r})")
    pairs = _records(records)
    file_options = {k: v for k, v in dict(inputs=inputs, outputs=outputs, time=time, ts=ts,
                                          intersample=intersample).items() if v is not None}
    writer = _writer(out, resume) if out is not None else None
    rows = {str(r["id"]): r for r in writer.rows} if writer else {}  # those of an earlier run (resume)
    todo = [(rid, rec) for rid, rec in pairs if rid not in rows]

    record_bytes = max((len(r) * (r.nu + r.ny + 1) * 8 for _, r in todo if isinstance(r, ctid.IdData)), default=0)
    size = chunk or _chunk_size(len(todo), _threads(client, jobs), record_bytes)
    chunks = [todo[i:i + size] for i in range(0, len(todo), size)]
    _execute(fit_chunk, [(c, method, options, file_options) for c in chunks], client, jobs, retries, rows, writer,
             progress, len(pairs) - len(todo), len(pairs), "fit_many")
    frame = pd.DataFrame([rows[rid] for rid, _ in pairs if rid in rows])
    for c in COLUMNS:
        if c not in frame:
            frame[c] = pd.Series(dtype=object)
    rest = [c for c in frame.columns if c not in COLUMNS]
    return frame[COLUMNS + rest].reset_index(drop=True)


def _truth(model):
    """The true parameters of a transfer function in the estimators' names: a1..an (denominator after its leading
    1), b0.. (numerator, highest power first), delay."""
    import ctid
    if not isinstance(model, ctid.TransferFunction):
        return {}
    truth = {f"a{i}": float(c) for i, c in enumerate(model.den) if i > 0}
    truth.update({f"b{j}": float(c) for j, c in enumerate(model.num)})
    if model.delay:
        truth["delay"] = float(model.delay)
    return truth


def _experiment(model, u, ts, t, intersample):
    """The noise-free record of the design: the model simulated exactly from rest on the input."""
    import numpy as np
    import ctid
    u = np.asarray(u, dtype=float)
    times = np.asarray(t, dtype=float) if t is not None else ctid.time_grid(ts, u.shape[0])
    x = model.simulate(u, times, intersample)
    if t is None:
        return ctid.IdData.from_arrays(u, x, ts=ts, intersample=intersample)
    return ctid.IdData.from_arrays(u, x, t=times, intersample=intersample)


def monte_carlo_chunk(model, u, ts, t, intersample, runs, snr_db, noise_std, method, options):
    """The rows of some runs of a Monte Carlo (run, seed pairs): the model's noise-free response computed once, the
    noise of each run drawn from its seed (ctid.add_noise_snr or ctid.white_noise, the same numbers on any machine),
    the record fitted by ctid.fit(record, method, **options)."""
    import numpy as np
    import ctid
    clean = _experiment(model, u, ts, t, intersample)
    x = np.asarray(clean.y)[:, 0]
    rows = []
    for run, seed in runs:
        t0 = _time.perf_counter()
        rid = f"{method}/{run}"
        try:
            y = ctid.add_noise_snr(x, snr_db, seed) if snr_db is not None else x + ctid.white_noise(x.size, noise_std, seed)
            if t is None:
                record = ctid.IdData.from_arrays(clean.u, y, ts=ts, intersample=intersample)
            else:
                record = ctid.IdData.from_arrays(clean.u, y, t=clean.t, intersample=intersample)
            result, ran, _ = ctid._fit(record, method, **options)
            row = _row(rid, ran, result)
        except Exception as e:  # noqa: BLE001 -- every failure becomes the row's error
            row = _row(rid, method, error=f"{type(e).__name__}: {e}", seconds=_time.perf_counter() - t0)
        row["run"], row["seed"] = run, seed
        rows.append(row)
    return rows


class MonteCarlo(tuple):
    """monte_carlo's answer: ``runs`` (one row per method and run: the estimates, their standard deviations, the
    fit's termination and usability) and ``summary`` (one row per method and parameter)."""
    __slots__ = ()

    def __new__(cls, runs, summary):
        return super().__new__(cls, (runs, summary))

    runs = property(lambda self: self[0])
    summary = property(lambda self: self[1])


def monte_carlo(model, u, ts=None, *, t=None, intersample="zoh", runs=100, snr_db=None, noise_std=None, seed=1000,
                methods="srivc", client=None, jobs=None, retries=2, chunk=None, progress=True, out=None,
                resume=False, **options):
    """A Monte Carlo study of estimators on a simulated experiment, on threads or a Dask cluster.

    model: the true system (a ctid model with .simulate, e.g. a TransferFunction). u: the input design (an array,
    e.g. ctid.prbs(...)), sampled every ts seconds or at the times t; intersample: "zoh" or "foh". Noise: white and
    Gaussian on the output, snr_db (variance = variance of the noise-free output / 10^(snr_db/10), as
    ctid.add_noise_snr) or noise_std; run k uses the seed seed + k, so every run is reproduced wherever it ran (the
    accuracy report's set-ups use seed=1000). methods: an estimator name, a list of names, or a dict name ->
    options; options (e.g. nb=2, nf=4) go to every method. client/jobs/retries/chunk/progress/out/resume: as
    fit_many (out holds the runs; resume continues an interrupted study).

    Returns MonteCarlo(runs, summary): `runs` has fit_many's columns plus run and seed; `summary` one row per method
    and parameter: true, mean, bias, std (over the usable runs), crlb_std (the Cramer-Rao bound, ctid.crlb, for a
    transfer function fitted with its own orders; NaN otherwise), std_over_crlb, bias_over_std, usable, runs.
    """
    import numpy as np
    import pandas as pd
    import ctid

    if (snr_db is None) == (noise_std is None):
        raise ValueError("monte_carlo: give the noise level as snr_db or as noise_std (one of them)")
    if noise_std is not None and not (np.isfinite(noise_std) and noise_std > 0):
        raise ValueError(f"monte_carlo: noise_std must be finite and > 0 (got {noise_std!r})")
    if not (isinstance(runs, int) and runs >= 1):
        raise ValueError(f"monte_carlo: runs must be a whole number >= 1 (got {runs!r})")
    if not (isinstance(seed, int) and seed >= 0):
        raise ValueError(f"monte_carlo: seed must be a whole number >= 0 (got {seed!r})")
    if (ts is None) == (t is None):
        raise ValueError("monte_carlo: give the sampling as ts (seconds) or as the sample times t (one of them)")
    per_method = {methods: {}} if isinstance(methods, str) else \
        dict(methods) if isinstance(methods, dict) else {m: {} for m in methods}
    for m in per_method:
        _check_method("monte_carlo", m, {})
    _check_jobs("monte_carlo", jobs)
    clean = _experiment(model, u, ts, t, intersample)  # checks the design here, before any task is sent
    x = np.asarray(clean.y)[:, 0]
    sigma2 = noise_std ** 2 if noise_std is not None else float(np.mean((x - x.mean()) ** 2)) / 10 ** (snr_db / 10)

    writer = _writer(out, resume) if out is not None else None
    rows = {str(r["id"]): r for r in writer.rows} if writer else {}
    threads = _threads(client, jobs)
    tasks, total = [], 0
    for m, own in per_method.items():
        opts = {**options, **own}
        todo = [(k, seed + k) for k in range(runs) if f"{m}/{k}" not in rows]
        total += runs
        size = chunk or _chunk_size(len(todo), threads)
        tasks += [(model, np.asarray(u, dtype=float), ts, t, intersample, todo[i:i + size], snr_db, noise_std, m, opts)
                  for i in range(0, len(todo), size)]
    _execute(monte_carlo_chunk, tasks, client, jobs, retries, rows, writer, progress, len(rows), total,
             "monte_carlo")

    order = [f"{m}/{k}" for m in per_method for k in range(runs)]
    frame = pd.DataFrame([rows[i] for i in order if i in rows])
    rest = [c for c in frame.columns if c not in COLUMNS + ["run", "seed"]]
    frame = frame[COLUMNS + ["run", "seed"] + rest].reset_index(drop=True)

    truth = _truth(model)
    summary = []
    for m, own in per_method.items():
        sub = frame[(frame["method"] == m) & (frame["usable"].astype(bool))]
        bound = None
        names = [c for c in rest if not c.endswith("_std") and c in sub and sub[c].notna().any()]
        if isinstance(model, ctid.TransferFunction) and names == [n for n in truth if n != "delay"]:
            bound = np.sqrt(np.diag(ctid.crlb(model, len(model.num), clean, sigma2)))
        for i, name in enumerate(names):
            v = sub[name].astype(float).to_numpy()
            true = truth.get(name, np.nan)
            mean = float(v.mean()) if v.size else np.nan
            std = float(v.std(ddof=1)) if v.size > 1 else np.nan
            crlb_std = float(bound[i]) if bound is not None else np.nan
            summary.append({"method": m, "parameter": name, "true": true, "mean": mean, "bias": mean - true,
                            "std": std, "crlb_std": crlb_std, "std_over_crlb": std / crlb_std,
                            "bias_over_std": abs(mean - true) / std, "usable": int(v.size),
                            "runs": int((frame["method"] == m).sum())})
    return MonteCarlo(frame, pd.DataFrame(summary))
