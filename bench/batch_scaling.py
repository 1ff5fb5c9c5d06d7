"""Batch identification on Dask (issue 18): records per second of ctid.batch.fit_many with 1 and 2 workers, the
scheduling overhead per record, and peak memory per worker.

    PYTHONPATH=build/python /usr/bin/python3 bench/batch_scaling.py [--records 2000] [--samples 10000]

Records: G(s) = 4/(s^2 + 0.8 s + 4) under a PRBS at Ts = 20 ms with 20 dB output noise (a seed each), fitted by
SRIVC with nb = 1, nf = 2. Configurations: a plain loop in this process (the reference), fit_many with the local
default (threads in this process) and jobs = 1, 2, and a LocalCluster of 1 and 2 worker processes (one thread each:
the records are pickled to the workers). Overhead per record: (batch time - loop time) / records on records of
200 samples, whose fit takes well under a millisecond.
"""
import argparse
import resource
import time

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


def batch(records, client=None, jobs=None):
    t = time.perf_counter()
    df = ctid.batch.fit_many(records, method="srivc", client=client, jobs=jobs, progress=False, nb=1, nf=2)
    dt = time.perf_counter() - t
    assert len(df) == len(records) and df["usable"].all(), df["error"].unique()[:3]
    return dt


def worker_rss(client):
    return max(client.run(lambda: resource.getrusage(resource.RUSAGE_SELF).ru_maxrss).values()) / 1024.0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--records", type=int, default=2000)
    ap.add_argument("--samples", type=int, default=10000)
    a = ap.parse_args()
    from distributed import Client, LocalCluster

    recs = make_records(a.records, a.samples)
    rows = [("plain loop in this process", 1, loop(recs), float("nan"))]
    for jobs in (1, 2):
        rows.append(("fit_many, client=None (threads)", jobs, batch(recs, jobs=jobs), float("nan")))
    for workers in (1, 2):
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0") as cl, \
                Client(cl) as c:
            rows.append(("fit_many, LocalCluster of processes", workers, batch(recs, client=c), worker_rss(c)))
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
