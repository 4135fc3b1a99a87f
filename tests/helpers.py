"""Independent geometry used by the tests, and a way to interrupt a run mid-way on any machine."""

import os
import signal
import time

import numpy as np


def nguyen(grasp) -> tuple[bool, float]:
    """Nguyen's two-finger condition and its distance to the boundary (radians).

    Force closure iff the line through the contacts lies strictly inside both friction cones,
    oriented the same way for both fingers: squeezing, angle(n1, p2 - p1) < atan(mu1) and
    angle(n2, p1 - p2) < atan(mu2); or spreading (an internal grasp, fingers pushing apart),
    angle(n1, p1 - p2) < atan(mu1) and angle(n2, p2 - p1) < atan(mu2).
    """
    a, b = grasp.contacts
    p1, p2 = np.array(a.p), np.array(b.p)
    d = (p2 - p1) / np.linalg.norm(p2 - p1)
    angle = lambda n, v: np.arccos(np.clip(np.dot(n, v), -1, 1))
    slack = max(
        min(np.arctan(a.mu) - angle(a.n, s * d), np.arctan(b.mu) - angle(b.n, -s * d))
        for s in (1, -1)
    )
    return bool(slack > 0), float(abs(slack))


def rotation(rng, dim):
    """A random proper rotation matrix."""
    q, r = np.linalg.qr(rng.normal(size=(dim, dim)))
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    return q


def interrupt_after(count: int):
    """A progress callback that raises KeyboardInterrupt at its ``count``-th call (a run stopped
    after ``count`` chunks, its parts kept)."""
    calls = []

    def progress(_size) -> None:
        calls.append(_size)
        if len(calls) == count:
            raise KeyboardInterrupt

    return progress


def signal_after(proc, count_parts, count: int, sig=signal.SIGKILL) -> bool:
    """Send ``sig`` to the process group of ``proc`` once ``count_parts()`` reaches ``count``,
    while the run is still going. The run advances in steps of a few milliseconds between
    SIGSTOP and SIGCONT and the parts are counted while it is stopped, so the signal always lands
    mid-run whatever the machine's speed or load. Returns False only when the run ended first."""
    while True:
        os.killpg(proc.pid, signal.SIGSTOP)
        done = count_parts()
        if proc.poll() is not None:
            return False
        if done >= count:
            os.killpg(proc.pid, sig)
            os.killpg(proc.pid, signal.SIGCONT)
            return True
        os.killpg(proc.pid, signal.SIGCONT)
        time.sleep(0.005)


def columnar_and_per_grasp(table, options):
    """Results rows of a grasp table by the columnar path and by the per-grasp path, and the
    rows the columnar path handed to the per-grasp path (imports inside: this module stays
    light for the tests that only need the geometry)."""
    from qualgrasp.certify.batch import certify_table
    from qualgrasp.certify.batch.chunk import certify_values
    from qualgrasp.certify.files import rows_to_table, table_to_rows, table_values

    lines = list(range(1, table.num_rows + 1))
    values = table_values(table)
    ref = table_to_rows(rows_to_table(list(certify_values(values, lines, options))))
    slow_rows = []

    def slow(idx):
        slow_rows.extend(idx)
        return list(certify_values([values[i] for i in idx], [lines[i] for i in idx], options))

    fast = table_to_rows(certify_table(table, lines, options, slow=slow))
    return fast, ref, slow_rows
