"""``qualgrasp bench``'s rows with quality: the batch path on planar grasps with quality against
its baselines, timed on the same grasps in the same run."""

from qualgrasp.certify.batch.chunk import Options
from qualgrasp.certify.batch.samples import random_grasp_table
from qualgrasp.experiments import bench

from helpers import columnar_and_per_grasp


def test_the_bench_times_planar_quality_against_its_baselines():
    """The bench's rows with quality: per kind the batch path with quality, the same grasps
    without it and the per-grasp route, ratios to the first; the batch path's results equal the
    per-grasp route's (the speed compared is that of the same rows)."""
    rows = bench._quality_rows(30, 2, 4)
    assert [r.kind for r in rows] == [f"{k}, with quality" for k in bench.BATCH_QUALITY_KINDS for _ in range(3)]
    for base, plain, per in zip(rows[::3], rows[1::3], rows[2::3]):
        assert (base.grasps, plain.grasps, per.grasps, base.ratio) == (30, 30, 4, 1.0)
        assert plain.ratio == plain.seconds / base.seconds and per.seconds > 0
    for kwargs in bench.BATCH_QUALITY_KINDS.values():
        table = random_grasp_table(2, 30, **kwargs)
        fast, ref, _ = columnar_and_per_grasp(table, Options(quality=True, eps_time=None))
        assert fast == ref
