"""Quality's time limit says so when it cuts a bound, and results never depend on the state of
numba's compile cache: compilation does not count against the limit."""

import json
import os
import subprocess
import sys

import pytest

from qualgrasp.certify import certify_grasp, force_closure, grasp_to_dict
from qualgrasp.certify.batch.chunk import Options, certify_values
from qualgrasp.certify.quality import verify_epsilon
from qualgrasp.certify.batch import certify_table
from qualgrasp.certify.quality import epsilons
from qualgrasp.certify.batch import random_grasps
from qualgrasp.certify.files import grasps_table, table_to_rows, table_values

# Planar grasps of every epsilon route: 21 point contacts (42 generators: the L-infinity sweep
# and `support` evidence refined under the clock), pads, frictionless, few points; and spatial.
PLANAR = dict(dim=2, n_contacts=21, model="point")
TINY = 1e-9  # seconds: no machine computes an epsilon this fast


def _closure(grasps):
    return [g for g in grasps if force_closure(g).status == "closure"]


def _columnar(dicts, options):
    """Rows of the columnar route (per-grasp route for the rows it leaves)."""
    table = grasps_table(dicts)
    values, lines = table_values(table), list(range(1, len(dicts) + 1))
    return table_to_rows(certify_table(table, lines, options, slow=lambda idx: certify_values(
        [values[i] for i in idx], [lines[i] for i in idx], options)))


def _bounds(e):
    return {norm: (x.lo, x.hi) for norm, x in e.items()}


def test_a_cut_planar_support_refinement_says_limited():
    """The deadline stops the refinement of the planar L-infinity `support` evidence (21
    contacts: one batch of the sweep, never cut by it): the lower bound reached is smaller, and
    ``limited`` says so, in the Epsilon, the per-grasp row and the columnar row."""
    g = _closure(random_grasps(8, 20, **PLANAR))[0]
    full, cut = epsilons(g), epsilons(g, time_limit=TINY)
    assert not full["Linf"].limited and full["Linf"].evidence.kind == "support"
    assert cut["Linf"].lo < full["Linf"].lo  # the refinement was cut ...
    assert cut["Linf"].limited  # ... and says so
    row = certify_grasp(g, eps_time=TINY).row(line=1)
    assert row["eps_limited"] is True and row["eps_linf_lo"] < full["Linf"].lo
    assert verify_epsilon(g, row, True)
    columnar = _columnar([grasp_to_dict(g)], Options(eps_time=TINY))
    assert columnar[0]["eps_limited"] is True and columnar[0]["eps_linf_lo"] < full["Linf"].lo


@pytest.mark.parametrize("kwargs", [PLANAR, dict(dim=2, n_contacts=14, model="point"),
                                    dict(dim=3, n_contacts=12, model="point", spread=0.3),
                                    dict(dim=3, n_contacts=6, model="soft")])
def test_every_bound_a_limit_changes_is_flagged(kwargs):
    """Whatever a tiny limit cuts (sweep, support refinement, spatial local minimisation or
    refinement), a bound that differs from the unlimited one comes with ``limited``; the
    bounds stay rigorous (they bracket the unlimited ones)."""
    for g in _closure(random_grasps(9, 12, **kwargs))[:3]:
        full, cut = epsilons(g), epsilons(g, time_limit=TINY)
        for norm in full:
            assert not full[norm].limited
            if (cut[norm].lo, cut[norm].hi) != (full[norm].lo, full[norm].hi):
                assert cut[norm].limited, (norm, _bounds(cut), _bounds(full))
            assert cut[norm].lo <= full[norm].hi * (1 + 1e-9) and cut[norm].hi >= full[norm].lo * (1 - 1e-9)


# Run in a fresh interpreter: the rows of both routes for fixed grasps, default options (the
# default time limit), as JSON.
_ROWS = """
import json
from qualgrasp.certify import grasp_to_dict
from qualgrasp.certify.batch.chunk import Options, certify_values
from qualgrasp.certify.batch.fastpath import certify_table
from qualgrasp.certify.batch.samples import random_grasps
from qualgrasp.certify.files.reader import grasps_table, rows_to_table, table_to_rows, table_values

dicts = [grasp_to_dict(g) for g in random_grasps(8, 6, dim=2, n_contacts=21, model="point")]
dicts += [grasp_to_dict(g) for g in random_grasps(7, 4, dim=2, n_contacts=3, model="pad", mu=(0.1, 0.8))]
dicts += [grasp_to_dict(g) for g in random_grasps(6, 3, dim=3, n_contacts=5, model="point")]
table = grasps_table(dicts)
lines = list(range(1, len(dicts) + 1))
values = table_values(table)
per_grasp = table_to_rows(rows_to_table(certify_values(values, lines, Options())))
columnar = table_to_rows(certify_table(table, lines, Options(),
                                       slow=lambda idx: certify_values([values[i] for i in idx],
                                                                       [lines[i] for i in idx], Options())))
print(json.dumps({"per_grasp": per_grasp, "columnar": columnar}, default=str))
"""


def _run(code, cache=None):
    """stdout of ``code`` run by a fresh interpreter, with ``cache`` as NUMBA_CACHE_DIR if given."""
    env = dict(os.environ) if cache is None else dict(os.environ, NUMBA_CACHE_DIR=str(cache))
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=1800)
    assert out.returncode == 0, out.stderr[-3000:]
    return out.stdout


@pytest.mark.slow
def test_rows_are_the_same_with_a_cold_and_a_warm_compile_cache(tmp_path):
    """The same grasps certified with quality (default time limit) in a process whose compile
    cache is empty (every kernel compiles, for tens of seconds) and in one whose cache is warm:
    identical rows, none limited, per-grasp and columnar routes alike. In the slow set (30 s of
    compiling); the test command checks that no kernel compiles under quality's clock (below)."""
    cache = tmp_path / "numba"
    cache.mkdir()
    cold = json.loads(_run(_ROWS, cache))
    assert any(cache.rglob("*.nbi")), "the first run did not compile into the empty cache"
    warm = json.loads(_run(_ROWS, cache))
    assert cold == warm
    assert cold["per_grasp"] == cold["columnar"]
    assert not any(r["eps_limited"] for r in cold["per_grasp"])
    assert any(r["eps_linf_lo"] is not None and r["eps_linf_lo"] > 0 for r in cold["per_grasp"])


# Every kernel's compiled signatures are counted where quality's clock starts (after its
# precompile) and again when the epsilons are returned: a kernel compiled (or loaded from the
# cache) under the clock adds one.
_NO_COMPILE_UNDER_THE_CLOCK = """
import importlib, pkgutil
import qualgrasp.certify._kernels as kernels
from qualgrasp.certify.quality import bounds as quality
from qualgrasp.certify.core.closure import force_closure
from qualgrasp.certify.batch.samples import random_grasps

grasps = (random_grasps(8, 4, dim=2, n_contacts=21, model="point") + random_grasps(7, 4, dim=2, n_contacts=3, model="pad")
          + random_grasps(5, 4, dim=2, n_contacts=4, model="frictionless") + random_grasps(4, 4, dim=2, n_contacts=9, model="point")
          + random_grasps(6, 4, dim=3, n_contacts=5, model="point") + random_grasps(3, 4, dim=3, n_contacts=4, model="soft"))
verdicts = [force_closure(g) for g in grasps]  # closure's kernels compile outside quality's clock
dispatchers = {(info.name, name): f for info in pkgutil.iter_modules(kernels.__path__)
               for name, f in vars(importlib.import_module("qualgrasp.certify._kernels." + info.name)).items()
               if hasattr(f, "signatures")}
real, counts = quality.precompile, {}

def precompile_then_count(signatures):
    real(signatures)
    counts.update({key: len(f.signatures) for key, f in dispatchers.items()})

quality.precompile = precompile_then_count
done = 0
for g, v in zip(grasps, verdicts):
    if v.status == "closure":
        quality.epsilons(g, verdict=v, time_limit=3600.0)
        grown = [key for key, f in dispatchers.items() if len(f.signatures) != counts[key]]
        assert not grown, f"compiled under the clock: {grown}"
        done += 1
print(done)
"""


def test_no_kernel_compiles_under_the_clock():
    """Every kernel quality calls under its clock is compiled before the clock starts (for the
    argument types it is called with), on every route: planar enumeration, sweep and support,
    pads, frictionless, spatial point and soft contacts."""
    done = int(_run(_NO_COMPILE_UNDER_THE_CLOCK).strip())
    assert done >= 12
