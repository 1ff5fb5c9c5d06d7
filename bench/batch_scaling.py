"""Batch identification on Dask (issue 18): records per second of ctid.batch.fit_many with 1 and 2 workers, the
scheduling overhead per record, and peak memory per worker.

    PYTHONPATH=build/python /usr/bin/python3 bench/batch_scaling.py [--records 2000] [--samples 10000] [--ctid build/ctid]

Records: G(s) = 4/(s^2 + 0.8 s + 4) under a PRBS at Ts = 20 ms with 20 dB output noise (a seed each), fitted by
SRIVC with nb = 1, nf = 2. Configurations: a plain loop in this process (the reference), fit_many with the local
default (threads in this process) and jobs = 1, 2, and a LocalCluster of 1 and 2 worker processes (one thread each:
the records are pickled to the workers), the same cluster given the records as files (.mat, each worker reads its
own: only the path and the options travel), and the command line `ctid batch DIR/*.mat --jobs 1, 2` on the same
files (peak RSS of the whole process). Each configuration is timed --repeats times (3) and the least time kept. Overhead per record: (batch time - loop time) / records on records of
200 samples, whose fit takes well under a millisecond.
"""
import argparse
import os
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
    ap.add_argument("--repeats", type=int, default=3, help="each configuration timed this often, the least kept")
    ap.add_argument("--ctid", default=os.path.join(os.path.dirname(__file__), "..", "build", "ctid"))
    a = ap.parse_args()
    from distributed import Client, LocalCluster

    recs = make_records(a.records, a.samples)
    rows = [("plain loop in this process", 1, best(lambda: loop(recs), a.repeats), float("nan"))]
    for jobs in (1, 2):
        rows.append(("fit_many, client=None (threads)", jobs, best(lambda: batch(recs, jobs=jobs), a.repeats), float("nan")))
    for workers in (1, 2):
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0") as cl, \
                Client(cl) as c:
            rows.append(("fit_many, LocalCluster of processes", workers, best(lambda: batch(recs, client=c), a.repeats),
                         worker_rss(c)))
    with tempfile.TemporaryDirectory() as folder:
        paths = write_files(recs, folder)
        os.sync()  # the files on disk before timing: no write-back of 320 MB shares the cores with the fits
        del recs
        files = dict(inputs="u", outputs="y", ts=0.02)
        for jobs in (1, 2):  # first: no cluster process still exiting shares the cores
            runs = [cli(a.ctid, folder, jobs) for _ in range(a.repeats)]
            dt, rss = min(r[0] for r in runs), max(r[1] for r in runs)
            rows.append(("ctid batch DIR/*.mat --jobs N (threads)", jobs, dt, rss))
        for workers in (1, 2):
            with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0") as cl, \
                    Client(cl) as c:
                rows.append(("fit_many, LocalCluster of processes, records as .mat files", workers,
                             best(lambda: batch(paths, client=c, **files), a.repeats), worker_rss(c)))
    print(f"{a.records} records of {a.samples} samples, SRIVC nb=1 nf=2")
    print("| configuration | workers | seconds | records/s | speed-up vs 1 worker | peak RSS per worker (MB) |")
    print("|---|---|---|---|---|---|")
    one = {name: dt for name, w, dt, _ in rows if w == 1}
    for name, w, dt, rss in rows:
        print(f"| {name} | {w} | {dt:.2f} | {a.records / dt:.0f} | {one[name] / dt:.2f} | "
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
