"""Batch identification on Dask (issue 18): records per second of ctid.batch.fit_many with 1 and 2 workers, the
scheduling overhead per record, and peak memory per worker.

    PYTHONPATH=build/python /usr/bin/python3 bench/batch_scaling.py [--records 2000] [--samples 10000] [--ctid build/ctid]

Records: G(s) = 4/(s^2 + 0.8 s + 4) under a PRBS at Ts = 20 ms with 20 dB output noise (a seed each), fitted by
SRIVC with nb = 1, nf = 2. Configurations: a plain loop in this process (the reference), fit_many with the local
default (threads in this process) and jobs = 1, 2, and a LocalCluster of 1 and 2 worker processes (one thread each:
the records are pickled to the workers), the same cluster given the records as files (.mat, each worker reads its
own: only the path and the options travel), and the command line `ctid batch DIR/*.mat --jobs 1, 2` on the same
files (peak RSS of the whole process). The speed of this shared machine drifts by 10-20 % from one minute to the next,
so the 1- and 2-worker runs of each configuration alternate (1, 2, 1, 2, ...; both clusters started and warmed
first), --repeats times each (5): the table gives each one's least time and, as the speed-up, the median of the
ratios of the runs paired in time (the ratio of the least times beside it). Overhead per record: (batch time - loop
time) / records on records of 200 samples, whose fit takes well under a millisecond.
"""
import argparse
import os
import statistics
import subprocess
import tempfile
import time

import scipy.io

import ctid
import ctid.batch


def make_records(n, samples):
    g = ctid.TransferFunction([4.0], [1.0, 0.8, 4.0])
    u = ctid.prbs(samples, register_length=11, clock_period=3)
    y = g.simulate(u, ctid.time_grid(0.02, samples))
    return [ctid.IdData.from_arrays(u, ctid.add_noise_snr(y, 20.0, i + 1), ts=0.02) for i in range(n)]


def loop(records):
    t = time.perf_counter()
    rs = [ctid.srivc(d, nb=1, nf=2) for d in records]
    assert all(r.usable() for r in rs)
    return time.perf_counter() - t


def best(run, repeats):
    """The least of `repeats` timings: the machine's other load only ever adds time."""
    return min(run() for _ in range(repeats))


def alternate(one, two, repeats):
    """Runs one() and two() in turn `repeats` times (each returns its seconds, or (seconds, peak RSS)): the least time
    of each, the largest peak of each (None without), and the median of the ratios one/two of the pairs, which the
    machine's drift in speed affects least."""
    a, b, ratios = [], [], []
    for _ in range(repeats):
        ra, rb = one(), two()
        a.append(ra if isinstance(ra, tuple) else (ra, None))
        b.append(rb if isinstance(rb, tuple) else (rb, None))
        ratios.append(a[-1][0] / b[-1][0])
    def peak(runs):
        return max(x for _, x in runs) if runs[0][1] is not None else None

    return min(t for t, _ in a), min(t for t, _ in b), peak(a), peak(b), statistics.median(ratios)


def write_files(records, folder):
    paths = []
    for i, d in enumerate(records):
        paths.append(os.path.join(folder, f"rec{i:05d}.mat"))
        scipy.io.savemat(paths[-1], {"u": d.u[:, 0], "y": d.y[:, 0]})
    return paths


def batch(records, client=None, jobs=None, **file_options):
    t = time.perf_counter()
    df = ctid.batch.fit_many(records, method="srivc", client=client, jobs=jobs, progress=False, nb=1, nf=2,
                             **file_options)
    dt = time.perf_counter() - t
    assert len(df) == len(records) and df["usable"].all(), df["error"].unique()[:3]
    return dt


def cli(tool, folder, jobs):
    out = os.path.join(folder, f"rows{jobs}.csv")
    if os.path.exists(out):
        os.remove(out)
    t = time.perf_counter()
    p = subprocess.Popen([tool, "batch", os.path.join(folder, "*.mat"), "--method", "srivc", "--nb", "1", "--nf", "2",
                          "--input", "u", "--output", "y", "--ts", "0.02", "--jobs", str(jobs), "--out", out],
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                         # the environment of a shell: distributed sets MALLOC_TRIM_THRESHOLD_=65536 in this process
                         # (for its workers), which makes every large allocation of a fit fault its pages anew
                         env={k: v for k, v in os.environ.items() if k != "MALLOC_TRIM_THRESHOLD_"})
    hwm = 0.0  # its peak RSS, VmHWM read every 20 ms (ru_maxrss of a child counts the forking Python's pages)
    while p.poll() is None:
        try:
            with open(f"/proc/{p.pid}/status") as f:
                hwm = max([hwm] + [int(x.split()[1]) / 1024.0 for x in f if x.startswith("VmHWM")])
        except OSError:
            pass
        time.sleep(0.02)
    dt = time.perf_counter() - t
    assert p.returncode == 0, p.stderr.read()
    return dt, hwm


def _vm_hwm():
    """Peak RSS of this process in MB since its exec (VmHWM; ru_maxrss would count the pages of the process it was
    forked from)."""
    with open("/proc/self/status") as f:
        return max(int(x.split()[1]) for x in f if x.startswith("VmHWM")) / 1024.0


def worker_rss(client):
    return max(client.run(_vm_hwm).values())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--records", type=int, default=2000)
    ap.add_argument("--samples", type=int, default=10000)
    ap.add_argument("--repeats", type=int, default=5, help="each configuration timed this often (alternating)")
    ap.add_argument("--ctid", default=os.path.join(os.path.dirname(__file__), "..", "build", "ctid"))
    a = ap.parse_args()
    from distributed import Client, LocalCluster

    recs = make_records(a.records, a.samples)
    rows = []  # (configuration, workers, seconds, peak RSS per worker, speed-up: median of paired ratios)

    def pair(name, one, two, rss=(float("nan"), float("nan"))):
        t1, t2, x1, x2, median = alternate(one, two, a.repeats)
        rows.append((name, 1, t1, x1 if x1 is not None else rss[0], float("nan")))
        rows.append((name, 2, t2, x2 if x2 is not None else rss[1], median))

    rows.append(("plain loop in this process", 1, best(lambda: loop(recs), a.repeats), float("nan"), float("nan")))
    pair("fit_many, client=None (threads)", lambda: batch(recs, jobs=1), lambda: batch(recs, jobs=2))

    def clusters(name, records, **options):
        """Both clusters started and warmed (ctid imported in every worker), then their runs alternate."""
        with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0") as cl1, \
                Client(cl1) as c1, \
                LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as cl2, \
                Client(cl2) as c2:
            for c in (c1, c2):
                batch(records[:40], client=c, **options)
            pair(name, lambda: batch(records, client=c1, **options), lambda: batch(records, client=c2, **options),
                 (worker_rss(c1), worker_rss(c2)))

    clusters("fit_many, LocalCluster of processes (records pickled)", recs)
    with tempfile.TemporaryDirectory() as folder:
        paths = write_files(recs, folder)
        os.sync()  # the files on disk before timing: no write-back of 320 MB shares the cores with the fits
        recs.clear()  # the records in memory no longer needed
        files = dict(inputs="u", outputs="y", ts=0.02)
        pair("ctid batch DIR/*.mat --jobs N (threads)", lambda: cli(a.ctid, folder, 1), lambda: cli(a.ctid, folder, 2))
        clusters("fit_many, LocalCluster of processes, records as .mat files", paths, **files)
    print(f"{a.records} records of {a.samples} samples, SRIVC nb=1 nf=2; least of {a.repeats} alternating runs")
    print("| configuration | workers | seconds | records/s | speed-up vs 1 worker (median of paired runs) | "
          "ratio of the least times | peak RSS per worker (MB) |")
    print("|---|---|---|---|---|---|---|")
    one = {name: dt for name, w, dt, _, _ in rows if w == 1}
    for name, w, dt, rss, median in rows:
        sp = "1.00" if w == 1 else f"{median:.2f}"
        print(f"| {name} | {w} | {dt:.2f} | {a.records / dt:.0f} | {sp} | {one[name] / dt:.2f} | "
              f"{'' if rss != rss else f'{rss:.0f}'} |")
    small = make_records(a.records, 200)
    t_small = loop(small)
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0") as cl, Client(cl) as c:
        batch(small[:20], client=c)  # warm the worker (import ctid)
        t_batch = batch(small, client=c)
    print(f"scheduling overhead per record (1 worker process, records of 200 samples): "
          f"{1e3 * (t_batch - t_small) / a.records:.2f} ms (loop {t_small:.2f} s, batch {t_batch:.2f} s)")


if __name__ == "__main__":
    main()
