"""``qualgrasp bench --jobs``: the offline job end to end against its per-grasp baselines. No
timing is asserted: what is checked is that every job ran its whole set through the engine with
two workers, no row unverified, its baselines timed, and the options."""

import pytest
from typer.testing import CliRunner

from qualgrasp.certify.errors import OptionError
from qualgrasp.cli import app
from qualgrasp.experiments.bench_jobs import JOB_KINDS, run_jobs_bench, select_jobs

runner = CliRunner()


def _check_jobs(jobs, labels):
    assert [j.kind for j in jobs] == labels
    for job in jobs:
        kwargs, _ = JOB_KINDS[job.kind]
        assert job.rows == (120 if kwargs["dim"] == 2 else 12) == sum(job.statuses.values())
        assert job.unverified == 0 and job.statuses.get("error", 0) == 0
        assert job.per_grasp_n == 6 and job.cvxpy_n == 2 and 0 <= job.cvxpy_failed <= 2
        assert min(job.wall, job.cpu, job.per_grasp, job.cvxpy) > 0


def test_a_job_word_is_whole_words_of_the_labels():
    assert select_jobs(["quality"]) == [label for label in JOB_KINDS if label.endswith(", quality")]
    assert select_jobs(["NO-quality", "no-quality"]) == [label for label in JOB_KINDS if label.endswith("--no-quality")]
    assert select_jobs(["point contacts, quality"]) == select_jobs(["quality"])
    with pytest.raises(OptionError, match="in no job's label"):  # the words of no label in that order
        select_jobs(["contacts, quality, spatial"])
    assert select_jobs([]) == list(JOB_KINDS)


def test_selected_jobs_certify_their_whole_sets_and_time_their_baselines():
    """The test command's share: the main job (planar with quality) and the degenerate set."""
    labels = select_jobs(["planar, 3 point contacts, quality", "degenerate"])
    assert labels == [list(JOB_KINDS)[0], list(JOB_KINDS)[2]]
    jobs, starts = run_jobs_bench(sizes={2: 120, 3: 12}, reference_n=6, startup=False, kinds=labels)
    assert starts == []
    _check_jobs(jobs, labels)


@pytest.mark.slow
def test_every_job_certifies_its_whole_set_and_times_its_baselines():
    jobs, starts = run_jobs_bench(sizes={2: 120, 3: 12}, reference_n=6, startup=False)
    assert starts == []
    _check_jobs(jobs, list(JOB_KINDS))
    # the degenerate set is what its label says: antipodal and collinear grasps, mostly not in closure
    assert jobs[2].statuses != jobs[3].statuses


@pytest.mark.parametrize("args, message", [
    (["--jobs", "--single"], "does not go with --single"),
    (["--jobs", "--quality"], "does not go with"),
    (["--quick"], "--quick goes with --jobs"),
    (["--job", "spatial"], "--job goes with --jobs"),
    (["--jobs", "--job", "cylinder"], "'cylinder' is in no job's label"),
    (["--jobs", "--job", " "], "holds no word"),
])
def test_jobs_options_are_checked(args, message):
    result = runner.invoke(app, ["bench", *args])
    assert result.exit_code == 2 and message in result.output, result.output
