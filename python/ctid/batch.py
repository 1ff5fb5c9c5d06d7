"""ctid.batch — one identification method over many records, on threads or a Dask cluster (issue 18).

``fit_many(records, method="srivc", client=None, **options)`` fits every record with the single-record function
``ctid.<method>`` and the same keyword arguments (``fit_many(paths, method="srivc", nb=1, nf=1)`` is
``ctid.srivc(data, nb=1, nf=1)`` per record) and returns a pandas DataFrame, one row per record. It runs on the
``dask.distributed`` client given (a cluster of several machines unchanged), or with ``client=None`` on a pool of
threads in this process (the fits release the GIL, so threads use every core without copying the records). A record that cannot be read or fitted, or whose fit is not usable, is a row with its error; a task lost
with its worker is run again by Dask (``retries``) and every record gives exactly one row. With ``out=`` the rows
are also written to a CSV or JSON-lines file as they arrive, so that ``resume=True`` continues an interrupted batch
with only the records not yet written.
"""
import csv as _csv
import json as _json
import math as _math
import os as _os
import sys as _sys
import time as _time

#: The columns every row has, in this order; then, per parameter NAME of the model, NAME and NAME_std.
COLUMNS = ["id", "method", "model", "orders", "fit_percent", "termination", "usable", "seconds", "error"]


def _orders(model):
    """The structure of a fitted linear model in the estimators' terms (nb, nf, delay; nx); '' for the others."""
    import ctid
    if isinstance(model, ctid.TransferFunction):
        s = f"nb={len(model.num)} nf={len(model.den) - 1}"
        return s + (f" delay={model.delay:.6g}" if model.delay else "")
    if isinstance(model, ctid.StateSpace):
        return f"nx={model.A.shape[0]}"
    if isinstance(model, ctid.MisoModel):
        return "; ".join(f"nb={len(g.num)} nf={len(g.den) - 1}" for g in model.channels)
    return ""


def _row(rid, method, result=None, error="", seconds=0.0):
    row = {"id": rid, "method": method, "model": "", "orders": "", "fit_percent": _math.nan, "termination": "",
           "usable": False, "seconds": seconds, "error": error}
    if result is not None:
        import ctid
        row["model"] = "modal" if isinstance(result.model, ctid.ModalModel) else ctid._ctid.model_type_name(result.model)
        row["orders"] = _orders(result.model)
        row["fit_percent"] = float(result.fit.fit_percent)
        row["termination"] = result.summary.termination
        row["usable"] = bool(result.usable())
        row["seconds"] = float(result.summary.seconds)
        row["error"] = "" if row["usable"] else result.why_not_usable()
        p = result.parameters
        for name, value, std in zip(p.names, p.values, p.std):
            row[name] = float(value)
            row[name + "_std"] = float(std)
    return row


def fit_one(rid, record, method, options, file_options):
    """One row: the record (an IdData or a file path) read and fitted by ctid.<method>(record, **options). Every
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
        result = getattr(ctid, method)(record, **options)
        return _row(rid, method, result)
    except Exception as e:  # noqa: BLE001 -- every failure becomes the row's error
        return _row(rid, method, error=f"{type(e).__name__}: {e}", seconds=_time.perf_counter() - t0)


def fit_chunk(items, method, options, file_options):
    """fit_one over several (id, record) pairs: one Dask task (a task costs about a millisecond of scheduling, as
    much as a fit of a few thousand samples)."""
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


class _Writer:
    """Rows appended to a CSV or JSON-lines file as they arrive (one flush per row). A CSV whose columns grow (a
    record with other parameter names) is rewritten once with the new header (temporary file, then rename)."""

    def __init__(self, path, resume):
        self.path = _os.fspath(path)
        self.jsonl = self.path.endswith((".jsonl", ".json", ".ndjson"))
        if not self.jsonl and not self.path.endswith(".csv"):
            raise ValueError(f"fit_many: out must end in .csv or .jsonl (got '{self.path}')")
        self.rows = []
        if _os.path.exists(self.path):
            if not resume:
                raise FileExistsError(f"fit_many: {self.path} exists; resume=True continues it (only the records "
                                      f"not in it are fitted), or remove it")
            self.rows = self._read()
        self.columns = list(COLUMNS)
        for r in self.rows:
            self._grow(r)

    def _read(self):
        with open(self.path, newline="") as f:
            if self.jsonl:
                return [_json.loads(line) for line in f if line.strip()]
            rows = list(_csv.DictReader(f))
        for r in rows:  # numbers back from text
            for k, v in r.items():
                if k in ("id", "method", "model", "orders", "termination", "error"):
                    continue
                r[k] = (v == "True") if k == "usable" else (float(v) if v != "" else _math.nan)
        return rows

    def _grow(self, row):
        new = [k for k in row if k not in self.columns]
        self.columns += new
        return bool(new)

    def add(self, row):
        grew = self._grow(row)
        self.rows.append(row)
        if self.jsonl:
            with open(self.path, "a") as f:
                f.write(_json.dumps({k: (None if isinstance(v, float) and _math.isnan(v) else v)
                                     for k, v in row.items()}) + "\n")
        elif grew or not _os.path.exists(self.path):
            tmp = self.path + ".tmp"
            with open(tmp, "w", newline="") as f:
                w = _csv.DictWriter(f, fieldnames=self.columns, restval="")
                w.writeheader()
                w.writerows(self.rows)
            _os.replace(tmp, self.path)
        else:
            with open(self.path, "a", newline="") as f:
                _csv.DictWriter(f, fieldnames=self.columns, restval="").writerow(row)


def _show(done, total, errors, final=False):
    _sys.stderr.write(f"\rfit_many: {done}/{total} records, {errors} with an error" + ("\n" if final else ""))
    _sys.stderr.flush()


def fit_many(records, method="srivc", client=None, *, out=None, resume=False, progress=True, retries=2, jobs=None,
             chunk=None,
             inputs=None, outputs=None, time=None, ts=None, intersample=None, **options):
    """Fit every record with ``ctid.<method>(record, **options)``; a pandas DataFrame, one row per record.

    records: file paths (read by ctid.load with inputs=, outputs= and time=/ts=/intersample=), IdData objects (id =
    position) or (id, IdData) pairs. method: the name of a single-record estimator of ctid ("srivc", "srivc_auto",
    "oe", "tfest", "ssest", "fsf", "greybox", ...); options: its keyword arguments, as for one record.
    client: a dask.distributed.Client (its cluster runs the fits: records and options are sent to the workers, the
    library is not); None: a pool of ``jobs`` threads (default: every core) in this process.
    out: a .csv or .jsonl file the rows are written to as they arrive; resume=True continues a batch that stopped
    (the records whose id is in `out` are not fitted again; without resume an existing file is an error, never
    overwritten). progress: True prints a line on stderr, a callable gets (done, total) after each row.
    retries: how often Dask runs a task again whose worker was lost. chunk: records per Dask task (default: enough
    tasks for 8 per worker thread, at most 32 records each, so that the scheduling of a task, about a millisecond, is
    small beside its fits while the load stays balanced).

    Columns: id, method, model (its type), orders, fit_percent, termination, usable, seconds, error ('' for a usable
    fit; the exception, or why the fit is not usable), then NAME and NAME_std for each parameter. Rows are in the
    order of `records`.
    """
    import pandas as pd
    import concurrent.futures as cf
    import ctid

    if not isinstance(method, str) or not callable(getattr(ctid, method, None)) or method.startswith("_"):
        raise ValueError(f"fit_many: '{method}' is not an estimator of ctid (ctid.methods() lists them)")
    if chunk is not None and not (isinstance(chunk, int) and chunk >= 1):
        raise ValueError(f"fit_many: chunk must be a whole number >= 1 (got {chunk!r})")
    pairs = _records(records)
    file_options = {k: v for k, v in dict(inputs=inputs, outputs=outputs, time=time, ts=ts,
                                          intersample=intersample).items() if v is not None}
    writer = _Writer(out, resume) if out is not None else None
    rows = {str(r["id"]): r for r in writer.rows} if writer else {}  # those of an earlier run (resume)
    todo = [(rid, rec) for rid, rec in pairs if rid not in rows]

    errors = sum(1 for r in rows.values() if r.get("error"))
    # The local default is a pool of threads in this process (the standard library's executor: the fits release
    # the GIL, and nothing is copied); a Dask client gets the same tasks as futures with retries.
    pool = cf.ThreadPoolExecutor(max_workers=jobs or _os.cpu_count() or 1) if client is None else None
    try:
        threads = pool._max_workers if pool else max(1, sum(client.nthreads().values()))
        size = chunk or max(1, min(32, -(-len(todo) // (8 * threads))))
        chunks = [todo[i:i + size] for i in range(0, len(todo), size)]
        if pool:
            futures = [pool.submit(fit_chunk, c, method, options, file_options) for c in chunks]
            as_completed = cf.as_completed
        else:
            from distributed import as_completed
            stamp = _time.time_ns()
            futures = [client.submit(fit_chunk, c, method, options, file_options, retries=retries,
                                     key=f"ctid-fit-{stamp}-{i}", pure=False) for i, c in enumerate(chunks)]
        done = len(pairs) - len(todo)
        last = 0.0
        for fut in as_completed(futures):
            chunk_rows = fut.result()
            if not pool:
                fut.release()
            for row in chunk_rows:
                rows[str(row["id"])] = row
                if writer:
                    writer.add(row)
                done += 1
                errors += bool(row["error"])
                if callable(progress):
                    progress(done, len(pairs))
            if progress is True and (_time.monotonic() - last > 0.5 or done == len(pairs)):
                last = _time.monotonic()
                _show(done, len(pairs), errors, final=done == len(pairs))
    finally:
        if pool:
            pool.shutdown(cancel_futures=True)
    frame = pd.DataFrame([rows[rid] for rid, _ in pairs if rid in rows])
    for c in COLUMNS:
        if c not in frame:
            frame[c] = pd.Series(dtype=object)
    rest = [c for c in frame.columns if c not in COLUMNS]
    return frame[COLUMNS + rest].reset_index(drop=True)
