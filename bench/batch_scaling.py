"""Batch identification on Dask: records per second of ctid.batch.fit_many with 1 and 2 workers, the
scheduling overhead per record, and peak memory per worker.

    PYTHONPATH=build/python /usr/bin/python3 bench/batch_scaling.py [--records 2000] [--samples 10000] [--ctid build/ctid]

Records: G(s) = 4/(s^2 + 0.8 s + 4) under a PRBS at Ts = 20 ms with 20 dB output noise (a seed each), fitted by
SRIVC with nb = 1, nf = 2. Configurations: a plain loop in this process (the reference), fit_many with the local
default (threads in this process) and jobs = 1, 2, a cluster of 1 and 2 worker processes (one thread each) from
ctid.batch.local_cluster given the records in memory (pickled to the workers), the same given the records as files
(.mat, each worker reads its own: only the path and the options travel), a LocalCluster with Dask's default settings
given the files (also with 32 records per task, the former default), and the command line
`ctid batch DIR/*.mat --jobs 1, 2` on the same files (peak RSS of the whole process).

The speed of this shared machine drifts by 10-20 % from one minute to the next, so the 1- and 2-worker runs of each
configuration alternate (1, 2, 1, 2, ...; each cluster started and warmed before its run and closed after it, so that
no idle cluster shares the cores), --repeats times each (5): the table gives each one's least time and, as the
speed-up, the median of the ratios of the runs paired in time (the ratio of the least times beside it). The CPU
beside the fits is the share of the CPU time used during a cluster's batch (all threads of the client and of the
worker processes) that the workers' fitting threads did not use: Dask's own work, which with 2 workers takes its
share of the 2 cores from the fits. Overhead per record: (batch time - loop time) / records on records of 200
samples, whose fit takes well under a millisecond.
"""
import argparse
import os
import statistics
import subprocess
import tempfile
import time

import psutil
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
    """Runs one() and two() in turn `repeats` times (each returns its seconds, or a dict of seconds "s", peak RSS
    "rss" and CPU beside the fits "beside"): per side the least time, the largest peak and the median CPU beside the
    fits (None without), and the median of the ratios one/two of the pairs, which the machine's drift in speed affects
    least."""
    a, b, ratios = [], [], []
    for _ in range(repeats):
        ra, rb = one(), two()
        a.append(ra if isinstance(ra, dict) else {"s": ra})
        b.append(rb if isinstance(rb, dict) else {"s": rb})
        ratios.append(a[-1]["s"] / b[-1]["s"])

    def summary(runs):
        rss = [r["rss"] for r in runs if r.get("rss") is not None]
        beside = [r["beside"] for r in runs if r.get("beside") is not None]
        return (min(r["s"] for r in runs), max(rss) if rss else None,
                statistics.median(beside) if beside else None)

    return summary(a), summary(b), statistics.median(ratios)


def thread_cpu():
    """CPU seconds of every thread of this process and of its children: {pid: {thread id: seconds}}."""
    me, out = psutil.Process(), {}
    for p in [me] + me.children(recursive=True):
        try:
            out[p.pid] = {t.id: t.user_time + t.system_time for t in p.threads()}
        except psutil.Error:
            pass
    return out


def beside_fits(before, after, workers):
    """The share of the CPU used during a batch that did not go to the fits: the busiest thread of each worker
    process runs the fits (and reads the files); every other thread of the workers and of this process (client,
    scheduler, nannies) is Dask's."""
    fit = other = 0.0
    for pid, threads in after.items():
        d = sorted((v - before.get(pid, {}).get(t, 0.0) for t, v in threads.items()), reverse=True)
        if pid in workers and d:
            fit += d[0]
            d = d[1:]
        other += sum(d)
    return other / (fit + other)


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
    return {"s": dt, "rss": hwm}


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
    rows = []  # (configuration, workers, seconds, peak RSS per worker, CPU beside the fits, speed-up)

    def pair(name, one, two):
        (t1, x1, c1), (t2, x2, c2), median = alternate(one, two, a.repeats)
        rows.append((name, 1, t1, x1, c1, None))
        rows.append((name, 2, t2, x2, c2, median))

    rows.append(("plain loop in this process", 1, best(lambda: loop(recs), a.repeats), None, None, None))
    pair("fit_many, client=None (threads)", lambda: batch(recs, jobs=1), lambda: batch(recs, jobs=2))

    def cluster_run(make, records, **options):
        """One timed batch on a cluster of its own, started and warmed (ctid imported in every worker) first and
        closed after: no idle cluster shares the cores with the run of the other."""
        with make() as cl, Client(cl) as c:
            batch(records[:40], client=c, **options)
            workers, before = set(c.run(os.getpid).values()), thread_cpu()
            seconds = batch(records, client=c, **options)
            return {"s": seconds, "rss": worker_rss(c), "beside": beside_fits(before, thread_cpu(), workers)}

    def clusters(name, records, lean, chunk=None, **options):
        """1 against 2 worker processes: ctid.batch.local_cluster (lean) or a LocalCluster with Dask's defaults."""
        if chunk:
            options["chunk"] = chunk

        def make(n):
            if lean:
                return lambda: ctid.batch.local_cluster(n, dashboard_address=":0")
            return lambda: LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0")
        pair(name, lambda: cluster_run(make(1), records, **options), lambda: cluster_run(make(2), records, **options))

    clusters("fit_many, ctid.batch.local_cluster (records pickled)", recs, lean=True)
    with tempfile.TemporaryDirectory() as folder:
        paths = write_files(recs, folder)
        os.sync()  # the files on disk before timing: no write-back of 320 MB shares the cores with the fits
        recs.clear()  # the records in memory no longer needed
        files = dict(inputs="u", outputs="y", ts=0.02)
        pair("ctid batch DIR/*.mat --jobs N (threads)", lambda: cli(a.ctid, folder, 1), lambda: cli(a.ctid, folder, 2))
        clusters("fit_many, ctid.batch.local_cluster, records as .mat files", paths, lean=True, **files)
        clusters("fit_many, LocalCluster with Dask's defaults, records as .mat files", paths, lean=False, **files)
        clusters("the same, 32 records per task (the former default)", paths, lean=False, chunk=32, **files)
    print(f"{a.records} records of {a.samples} samples, SRIVC nb=1 nf=2; least of {a.repeats} alternating runs")
    print("| configuration | workers | seconds | records/s | speed-up vs 1 worker (median of paired runs) | "
          "ratio of the least times | CPU beside the fits (median) | peak RSS per worker (MB) |")
    print("|---|---|---|---|---|---|---|---|")
    one = {name: dt for name, w, dt, *_ in rows if w == 1}
    for name, w, dt, rss, beside, median in rows:
        sp = "1.00" if w == 1 else f"{median:.2f}"
        print(f"| {name} | {w} | {dt:.2f} | {a.records / dt:.0f} | {sp} | {one[name] / dt:.2f} | "
              f"{'' if beside is None else f'{100 * beside:.1f} %'} | {'' if rss is None else f'{rss:.0f}'} |")
    small = make_records(a.records, 200)
    t_small = loop(small)
    with ctid.batch.local_cluster(1, dashboard_address=":0") as cl, Client(cl) as c:
        batch(small[:20], client=c)  # warm the worker (import ctid)
        t_batch = batch(small, client=c)
    print(f"scheduling overhead per record (1 worker process, records of 200 samples): "
          f"{1e3 * (t_batch - t_small) / a.records:.2f} ms (loop {t_small:.2f} s, batch {t_batch:.2f} s)")


if __name__ == "__main__":
    main()
