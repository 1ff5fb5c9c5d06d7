"""Timing helper of the Python benchmarks (bench/*.py; importable because a script's folder is on sys.path)."""
import time


def least_time(f, repeats=3, slow=float("inf")):
    """(the least time in seconds of `repeats` calls of f, the last call's result). The other load of the machine
    only ever adds time, so the least is the one to compare; a first call slower than `slow` seconds is not
    repeated."""
    times, out = [], None
    for _ in range(repeats):
        t = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t)
        if times[0] > slow:
            break
    return min(times), out
