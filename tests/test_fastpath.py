"""The columnar fast path gives, row for row, what the per-grasp path gives."""

import numpy as np
import pyarrow as pa
import pytest

from qualgrasp.certify import Contact, Grasp, force_closure, verify
from qualgrasp.certify.batch import verify_file
from qualgrasp.certify.batch.chunk import Options
from qualgrasp.certify.batch import certify_table
from qualgrasp.certify.core import grasp_from_dict, grasp_to_dict
from qualgrasp.certify.batch import random_grasp_table, random_grasps, textbook_grasps
from qualgrasp.certify.files import grasps_table, rows_to_table, table_to_rows

from helpers import columnar_and_per_grasp


def _dicts():
    out = []
    for kw in (dict(n_contacts=3, model="point"), dict(n_contacts=4, model="frictionless"),
               dict(n_contacts=2, model="point", spread=0.4), dict(n_contacts=1, model="point"),
               dict(n_contacts=5, model="frictionless"), dict(n_contacts=4, model="point")):
        out += [grasp_to_dict(g) for g in random_grasps(3, 150, dim=2, **kw)]
    mixed = [Grasp((Contact((1, 0.2), (-1, 0), "point", 0.4), Contact((-1, 0.1), (1, 0)),
                    Contact((0.1, 1), (0, -1)), Contact((0, -1), (0, 1), "point", 0.0)), id=f"mix{i}",
                   center=(0.01 * i, 0), length=1 + i) for i in range(20)]
    out += [grasp_to_dict(g) for g in mixed + textbook_grasps()]
    for d in out[::3]:
        d.pop("center")
        d.pop("length")
    bad = [
        {"id": "nan", "contacts": [{"p": [float("nan"), 0], "n": [1, 0]}]},
        {"id": "zero", "contacts": [{"p": [0, 0], "n": [0, 0]}]},
        {"id": "negmu", "contacts": [{"p": [0, 0], "n": [1, 0], "model": "point", "mu": -1}]},
        {"id": "mixed", "contacts": [{"p": [0, 0], "n": [1, 0]}, {"p": [0, 0, 1], "n": [1, 0, 0]}]},
        {"id": "soft2d", "contacts": [{"p": [0, 0], "n": [1, 0], "model": "soft", "mu": 1, "torsion": 1}]},
        {"id": "glue", "contacts": [{"p": [0, 0], "n": [1, 0], "model": "glue"}]},
        {"id": "empty", "contacts": []},
        {"id": "fricmu", "contacts": [{"p": [0, 0], "n": [1, 0], "model": "frictionless", "mu": 0.3}]},
        {"id": "len0", "contacts": [{"p": [0, 0], "n": [1, 0]}], "length": 0},
        {"id": "nonunit", "contacts": [{"p": [1, 0], "n": [-3, 0.4], "mu": 0.5},
                                       {"p": [-1, 0], "n": [2, 0.1], "mu": 0.5}]},
    ]
    return out + bad


@pytest.mark.parametrize("quality", [False, True])
def test_columnar_rows_equal_per_grasp_rows(quality):
    table = grasps_table(_dicts())
    fast, ref, slow = columnar_and_per_grasp(table, Options(quality=quality))
    assert len(fast) == len(ref) == table.num_rows
    for a, b in zip(fast, ref):
        assert a == b, (a["id"], {k: (a[k], b[k]) for k in a if a[k] != b[k]})
    # most rows took the columnar path: only invalid, thin or borderline ones did not
    assert len(slow) < 0.1 * table.num_rows


def test_fast_results_verify(tmp_path):
    table = random_grasp_table(5, 3000, dim=2, n_contacts=3, model="point")
    lines = list(range(1, 3001))
    res = certify_table(table, lines, Options(quality=False), slow=lambda idx: [])
    grasps, results = tmp_path / "g.parquet", tmp_path / "r.parquet"
    import pyarrow.parquet as pq

    pq.write_table(table, grasps)
    pq.write_table(res, results)
    summary = verify_file(results, grasps, workers=2)
    assert summary.rows == 3000 and not summary.failures
    statuses = res.column("status").value_counts().to_pylist()
    assert {s["values"] for s in statuses} == {"closure", "no_closure"}


def test_bulk_recheck_rejects_tampered_rows(tmp_path):
    """The columnar re-check catches the same tampering as the exact one, planar and spatial."""
    import pyarrow.parquet as pq

    from qualgrasp.certify.batch import certify_file

    grasps = random_grasps(4, 150, dim=2, n_contacts=3) + [
        Grasp(g.contacts, id=f"s{i}") for i, g in enumerate(
            random_grasps(5, 60, dim=3, n_contacts=3, model="point", spread=0.3))]
    gpath, rpath = tmp_path / "g.parquet", tmp_path / "r.parquet"
    from qualgrasp.certify.files import write_grasps

    write_grasps(gpath, grasps)
    certify_file(gpath, rpath, quality=False, chunk_size=64)
    assert not verify_file(rpath, gpath).failures
    rows = table_to_rows(pq.read_table(rpath))
    tampered = set()
    for dim in (2, 3):
        for kind in ("interior", "farkas"):
            row = next(r for r in rows if r["dim"] == dim and r["certificate"]["force"]["kind"] == kind
                       and r["id"] not in tampered)
            cert = row["certificate"]["force"]
            if kind == "interior":
                cert["values"] = [-v for v in cert["values"]]
            else:
                cert["y"] = [-v for v in cert["y"]]
            tampered.add(row["id"])
    row = next(r for r in rows if r["status"] == "closure" and r["id"] not in tampered)
    row["margin"] *= 3  # more margin than the forces show
    tampered.add(row["id"])
    pq.write_table(rows_to_table(rows), rpath)
    failures = verify_file(rpath, gpath, workers=2).failures
    assert {gid for gid, _ in failures} == tampered


def _spatial_dicts():
    out = []
    for seed, kw in enumerate((dict(n_contacts=3, model="point", spread=0.3),
                               dict(n_contacts=2, model="soft", spread=0.15),
                               dict(n_contacts=4, model="point", spread=0.3),
                               dict(n_contacts=6, model="point", spread=0.5),
                               dict(n_contacts=7, model="frictionless"),
                               dict(n_contacts=10, model="frictionless"),
                               dict(n_contacts=9, model="point", spread=0.5))):
        out += [grasp_to_dict(g) for g in random_grasps(20 + seed, 80, dim=3, **kw)]
    for d in out[::4]:
        d.pop("center")
        d.pop("length")
    # the cube held by seven frictionless contacts (form closure), and by six (not)
    cube = next(g for g in textbook_grasps() if g.dim == 3 and len(g.contacts) == 7)
    out.append(grasp_to_dict(cube))
    out.append(grasp_to_dict(Grasp(cube.contacts[:6], id="cube6")))
    return out


def test_spatial_columnar_rows_equal_per_grasp_rows():
    """Spatial groups (exact cones; frictionless or six-plus-contact LPs, by the batch barrier
    method from nine contacts on, else row by row, with float-proved certificates) give the
    per-grasp rows exactly."""
    table = grasps_table(_spatial_dicts())
    fast, ref, slow = columnar_and_per_grasp(table, Options(quality=False))
    assert len(fast) == len(ref) == table.num_rows
    for a, b in zip(fast, ref):
        assert a == b, (a["id"], {k: (a[k], b[k]) for k in a if a[k] != b[k]})
    assert len(slow) < 0.1 * table.num_rows
    statuses = {(r["n_contacts"], r["status"]) for r in fast}
    assert (10, "closure") in statuses and (10, "no_closure") in statuses
    forms = {(r["n_contacts"], r["form_status"]) for r in fast}
    assert (9, "closure") in forms and (9, "no_closure") in forms
    # two point contacts squeezing, decided by the closed-form squeeze direction on both routes
    assert sum(1 for r in fast if r["dim"] == 3 and r["certificate"]["force"].get("tight")) >= 3


def test_parsed_json_values_columnar_equal_per_grasp():
    """certify_parsed (JSON Lines chunks, certify --mesh) gives exactly the rows of the per-grasp
    route: ids of every JSON type as read, carried fields, bad values and unreadable lines."""
    import json

    from qualgrasp.certify.batch.chunk import certify_parsed, certify_values
    from qualgrasp.certify.errors import GraspFileError

    values = []
    for dim, m, model in ((2, 3, "point"), (2, 4, "frictionless"), (3, 3, "point"), (3, 2, "soft")):
        values += [grasp_to_dict(g) for g in random_grasps(5, 40, dim=dim, n_contacts=m, model=model)]
    for i, v in enumerate(values):
        v["id"] = [i, str(i), None, 1.5, True][i % 5]
        if i % 7 == 0:
            v["note"] = {"k": [i, "x"]}
    values[3]["contacts"][0]["mu"] = -1
    values[4]["contacts"] = "x"
    values[6]["extra"] = float("nan")  # cannot be carried: an error row saying so
    values.append(GraspFileError("malformed JSON"))
    lines = list(range(1, len(values) + 1))
    fast, ref = certify_parsed(values, lines, Options()), certify_values(values, lines, Options())
    assert [json.dumps(r) for r in fast] == [json.dumps(r) for r in ref]
    errors = {i for i, r in enumerate(ref) if r["status"] == "error"}
    assert {3, 4, 6, len(values) - 1} <= errors
    kept = [r["id"] for i, r in enumerate(ref) if i not in errors]
    assert {type(v) for v in kept} == {int, str, type(None)} and len(kept) >= 90


_EPSILON_GROUPS = ((3, "point"), (5, "point"), (3, "pad"), (5, "pad"), (10, "point"), (2, "point"))


def _epsilon_table(count):
    """Random planar grasps of the epsilon groups (3 and 5 contacts, point and pad models, and
    a few of 10 and 2 contacts), ``count`` in all; about half are in force closure."""
    import pyarrow as pa

    from qualgrasp.certify.batch.samples import random_grasp_table

    sizes = [count * 3 // 10] * 2 + [count // 10] * 2 + [count // 20] * 2
    sizes[0] += count - sum(sizes)
    return pa.concat_tables([random_grasp_table(40 + i, n, n_contacts=m, model=model, spread=0.4,
                                                start=sum(sizes[:i]))
                             for i, ((m, model), n) in enumerate(zip(_EPSILON_GROUPS, sizes))])


def _epsilon_rows_agree(count, monkeypatch, tmp_path):
    """The columnar epsilon columns and evidence equal the per-grasp route's on ``count`` grasps,
    are re-checked by ``verify``, and were computed for the whole group (the per-grasp
    function :func:`planar_epsilons` was called for few closure rows)."""
    import pyarrow.parquet as pq

    from qualgrasp.certify.batch import fastpath
    from qualgrasp.certify.batch.chunk import certify_values
    from qualgrasp.certify.files import table_values
    from qualgrasp.certify.quality import bounds

    table = _epsilon_table(count)
    options = Options(quality=True)
    lines = list(range(1, table.num_rows + 1))
    values = table_values(table)
    ref = table_to_rows(rows_to_table(list(certify_values(values, lines, options))))
    calls, inside_slow = [], []
    real = bounds.planar_epsilons

    def counted(*args, **kwargs):
        if not inside_slow:
            calls.append(1)
        return real(*args, **kwargs)

    def slow(idx):
        inside_slow.append(1)
        try:
            return list(certify_values([values[i] for i in idx], [lines[i] for i in idx], options))
        finally:
            inside_slow.pop()

    monkeypatch.setattr(bounds, "planar_epsilons", counted)
    monkeypatch.setattr(fastpath, "planar_epsilons", counted, raising=False)  # wherever it is called from
    res = certify_table(table, lines, options, slow=slow)
    fast = table_to_rows(res)
    assert len(fast) == len(ref) == table.num_rows
    for a, b in zip(fast, ref):
        assert a == b, (a["id"], {k: (a[k], b[k]) for k in a if a[k] != b[k]})
    closure = [r for r in fast if r["status"] == "closure"]
    kinds = {(r["n_contacts"], r["eps_evidence"]["linf"]["kind"]) for r in closure}
    assert {(3, "sums"), (5, "sums"), (10, "support")} <= kinds
    assert len(closure) > 0.3 * count and len(calls) <= 0.02 * len(closure)
    grasps, results = tmp_path / "g.parquet", tmp_path / "r.parquet"
    pq.write_table(table, grasps)
    pq.write_table(res, results)
    summary = verify_file(results, grasps, workers=2)
    assert summary.rows == count and not summary.failures


def test_columnar_epsilon_evidence_equals_per_grasp(monkeypatch, tmp_path):
    """Planar epsilon bounds and evidence compiled for a whole group: the per-grasp rows exactly
    (3 and 5 contacts, point and pad models; ``sums``, ``support`` and ``generators`` evidence),
    and ``verify`` accepts them."""
    _epsilon_rows_agree(1000, monkeypatch, tmp_path)


@pytest.mark.slow
def test_columnar_epsilon_evidence_equals_per_grasp_10000(monkeypatch, tmp_path):
    """The same on 10,000 grasps."""
    _epsilon_rows_agree(10000, monkeypatch, tmp_path)


def test_spatial_grasps_mixing_frictionless_and_friction_contacts_verify():
    """A frictionless contact among point or soft ones: its certificate value is the one force
    along its normal (force_columns' single column), so closure certificates verify, grasp by
    grasp and columnar alike (each stated three world-frame values once: 122 of 122 refused)."""
    dicts = []
    for model in ("point", "soft"):
        for g in random_grasps(3, 80, dim=3, n_contacts=5, model=model):
            d = grasp_to_dict(g)
            d["contacts"][0] = {"p": d["contacts"][0]["p"], "n": d["contacts"][0]["n"], "model": "frictionless"}
            dicts.append(d)
    table = grasps_table(dicts)
    fast, ref, _ = columnar_and_per_grasp(table, Options(quality=False))
    assert fast == ref
    closure = [r for r in ref if r["status"] == "closure"]
    assert len(closure) >= 40 and all(r["verified"] for r in ref)
    for d, r in zip(dicts[:40], ref[:40]):
        g = grasp_from_dict(d)
        v = force_closure(g)
        assert verify(g, v.certificate, status=v.status), (r["id"], v)


def _arc_grasps(seed: int, count: int, m: int, model: str = "point") -> list:
    """Grasps of ``m`` contacts on an arc of a blob 60 to 220 degrees wide: the narrow arcs are
    not in closure (strict Farkas directions), the wide ones are."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(count):
        a = rng.uniform(0, np.radians(rng.uniform(60, 220)), size=m)
        u = np.stack([np.cos(a), np.sin(a)], axis=1)
        p = u * rng.uniform(0.7, 1.3, size=(m, 1))
        n = -u + 0.3 * rng.normal(size=(m, 2))
        mu = rng.uniform(0.1, 0.6, size=m)
        extra = {"width": 0.1} if model == "pad" else {}
        out.append(Grasp(tuple(Contact(p[j], n[j], model, mu=mu[j], **extra) for j in range(m)), id=f"arc{seed}-{i}"))
    return out


@pytest.mark.parametrize("quality", [False, True])
def test_planar_rows_beyond_enumeration_equal_per_grasp_rows(quality):
    """Planar groups whose force-closure LP has more than 4,096 bases (over 30 generators: 16
    point contacts, 9 pads) take the batch barrier method with certificates proved in floats,
    form closure the enumeration: the per-grasp rows exactly, and hardly any row left to the
    per-grasp route (before, every such row went there)."""
    grasps = (random_grasps(1, 40, dim=2, n_contacts=16) + random_grasps(2, 30, dim=2, n_contacts=20)
              + random_grasps(3, 30, dim=2, n_contacts=9, model="pad") + _arc_grasps(6, 40, 16)
              + _arc_grasps(7, 30, 24) + _arc_grasps(8, 30, 9, "pad"))
    table = pa.concat_tables([grasps_table([grasp_to_dict(g) for g in grasps]),
                              random_grasp_table(4, 30, dim=2, n_contacts=16, degenerate="antipodal-disc")])
    fast, ref, slow = columnar_and_per_grasp(table, Options(quality=quality))
    assert len(fast) == len(ref) == table.num_rows
    for a, b in zip(fast, ref):
        assert a == b, (a["id"], {k: (a[k], b[k]) for k in a if a[k] != b[k]})
    assert len(slow) < 0.05 * table.num_rows, len(slow)
    statuses = {(r["n_contacts"], r["status"], r["form_status"]) for r in fast}
    assert {(16, "closure", "closure"), (16, "closure", "no_closure"), (16, "no_closure", "no_closure"),
            (24, "no_closure", "no_closure"), (9, "closure", "closure"), (9, "no_closure", "no_closure"),
            (16, "closure", "degenerate")} <= statuses
