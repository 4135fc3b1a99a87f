"""The grasp model: validation, normalisation, defaults, schema round trip."""

import math

import pytest

from qualgrasp.certify import Contact, Grasp, GraspError, grasp_from_dict, grasp_to_dict


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(p=(0, float("nan")), n=(1, 0)), "NaN or infinite"),
        (dict(p=(0, 0), n=(float("inf"), 0)), "NaN or infinite"),
        (dict(p=(0, 0), n=(0, 0)), "normal n is zero"),
        (dict(p=(0, 0), n=(1e-12, 0)), "normal n is zero"),
        (dict(p=(0, 0), n=(1, 0), model="point", mu=-0.1), "mu must be >= 0"),
        (dict(p=(0, 0), n=(1, 0), model="point", mu=float("nan")), "mu must be finite"),
        (dict(p=(0, 0, 0), n=(1, 0)), "p has 3 coordinates but normal n has 2"),
        (dict(p=(0, 0), n=(1, 0), model="sticky"), "unknown contact model"),
        (dict(p=(0, 0), n=(1, 0), model="soft", mu=0.5, torsion=0.1), "spatial only"),
        (dict(p=(0, 0, 0), n=(1, 0, 0), model="soft", mu=0.5), "needs its torsional length"),
        (dict(p=(0, 0, 0), n=(1, 0, 0), model="point", mu=0.5, torsion=0.1), "soft contacts only"),
        (dict(p=(0, 0), n=(1, 0), mu=0.3), "takes no mu"),
        (dict(p=(0,), n=(1,)), r"2 \(planar\) or 3 \(spatial\)"),
    ],
)
def test_bad_contacts_name_the_problem(kwargs, message):
    with pytest.raises(GraspError, match=message):
        Contact(**kwargs)


def test_bad_grasps_name_the_problem():
    with pytest.raises(GraspError, match="at least one contact"):
        Grasp(())
    with pytest.raises(GraspError, match="mix dimensions"):
        Grasp((Contact((0, 0), (1, 0)), Contact((0, 0, 0), (1, 0, 0))))
    with pytest.raises(GraspError, match="length must be > 0"):
        Grasp((Contact((0, 0), (1, 0)),), length=0)
    with pytest.raises(GraspError, match="center has 3"):
        Grasp((Contact((0, 0), (1, 0)),), center=(0, 0, 0))
    # extra fields inside a contact are ignored, from JSON and Parquet alike (issue 17; they
    # were an error before)
    assert grasp_from_dict({"contacts": [{"p": [0, 0], "n": [1, 0], "friction": 1}]}).contacts[0].model \
        == "frictionless"
    with pytest.raises(GraspError, match="needs a 'contacts' list"):
        grasp_from_dict({"id": "x"})


def test_non_unit_normals_are_normalised_and_unit_ones_kept_exactly():
    c = Contact((0, 0), (3, 4))
    assert c.n == (0.6, 0.8)
    n = (math.cos(0.3), math.sin(0.3))  # unit only up to rounding
    assert Contact((0, 0), n).n == n


def test_zero_friction_is_frictionless():
    c = Contact((0, 0, 0), (0, 0, 1), "soft", 0.0, 0.1)
    assert c.model == "frictionless" and c.torsion is None


def test_defaults_are_centroid_and_largest_reach():
    g = Grasp((Contact((0, 0), (1, 0)), Contact((4, 0), (-1, 0)), Contact((2, 3), (0, -1))))
    assert g.center == (2.0, 1.0)
    assert g.length == pytest.approx(math.sqrt(5))  # reach to (0, 0) and (4, 0); (2, 3) is at 2
    single = Grasp((Contact((1, 1), (1, 0)),))
    assert single.center == (1.0, 1.0) and single.length == 1.0


def test_schema_round_trip_keeps_everything():
    d = {"id": "g7", "contacts": [
        {"p": [1, 2, 3], "n": [0, 0, -1], "model": "soft", "mu": 0.4, "torsion": 0.2},
        {"p": [1, 2, -3], "n": [0, 0, 1], "model": "point", "mu": 0.4},
        {"p": [0, 1, 0], "n": [0, -1, 0]}],
        "center": [0, 0, 0], "length": 2.5, "regions": [3, 4]}
    g = grasp_from_dict(d)
    assert g.meta == {"regions": [3, 4]}
    assert grasp_from_dict(grasp_to_dict(g)) == g
    assert [c.model for c in g.contacts] == ["soft", "point", "frictionless"]


# --- the scalar rules of one contact or grasp against the rules on arrays ---------------------------

from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402
import numpy as np  # noqa: E402

from qualgrasp.certify import models as registry  # noqa: E402
from qualgrasp.certify.batch import random_grasps  # noqa: E402
from qualgrasp.certify.core.validation import (MIN_NORMAL, GraspData, check_contact, check_contacts,  # noqa: E402
                                               contact_arrays, contact_data, grasp_geometry, grasp_rules, param_names)
from qualgrasp.certify.files.columns import value_columns  # noqa: E402
from qualgrasp.certify.models import MAX_LENGTH  # noqa: E402
from qualgrasp.certify.core.grasp import _checked_of  # noqa: E402

_FLOATS = st.one_of(
    st.floats(-3, 3), st.floats(allow_nan=True, allow_infinity=True), st.sampled_from([0.0, -0.0, 1.0, -1.0, 1e-160,
                                                                                      5e-324, 1e6, 1e6 + 1, 1e154]),
    st.integers(-3, 3), st.just(10**400), st.booleans(), st.just("1"))
_VECTORS = st.one_of(st.lists(_FLOATS, min_size=1, max_size=4), st.tuples(st.floats(-2, 2), st.floats(-2, 2)),
                     st.tuples(st.floats(-2, 2), st.floats(-2, 2), st.floats(-2, 2)),
                     st.lists(st.floats(-2, 2), min_size=2, max_size=3).map(np.array),
                     st.lists(st.floats(-1, 1), min_size=2, max_size=3).map(  # unit to within rounding
                         lambda v: [x / math.hypot(*v) for x in v] if math.hypot(*v) > 0.1 else v), st.none())
_PARAMS = st.one_of(st.none(), st.floats(0, 2), st.sampled_from([0.0, -0.0, -0.1, 1e-300, 5e-324, 1e7]),
                    st.floats(allow_nan=True, allow_infinity=True), st.booleans(), st.integers(-1, 2))
_MODELS = st.one_of(st.none(), st.sampled_from(registry.names()), st.just("sticky"), st.just(3))


def _bits(values) -> list[str]:
    return [float(v).hex() for v in values]


def _reference_contact(value):
    """The contact as the rules on arrays give it (None: a rule fails)."""
    checked = check_contacts(contact_data([value]))
    if checked.error[0] is not None:
        return None
    dim, model = int(checked.dim[0]), registry.get(int(checked.model[0]))
    return (checked.p[0, :dim], checked.n[0, :dim], model.name,
            [(name, checked.params[name][0]) for name in model.param_names])


@settings(max_examples=800, deadline=None, suppress_health_check=list(HealthCheck))
@given(p=_VECTORS, n=_VECTORS, model=_MODELS, params=st.fixed_dictionaries({k: _PARAMS for k in param_names()}))
def test_one_contacts_rules_give_the_array_rules_values_bit_for_bit(p, n, model, params):
    value = {"p": p, "n": n, "model": model, **params}
    fast, ref = check_contact(value), _reference_contact(value)
    if fast is None:  # declined: the rules on arrays decide (a failed rule, a reduction, the default rule)
        return
    assert ref is not None, value
    assert _bits(fast[0]) == _bits(ref[0]) and _bits(fast[1]) == _bits(ref[1]), value
    assert fast[2] == ref[2] and [(k, float(v).hex()) for k, v in fast[3]] == [(k, float(v).hex()) for k, v in ref[3]]


def test_ordinary_contacts_take_the_scalar_rules_and_keep_their_values():
    """Every contact of random grasps of each model (and unit and non-unit normals) goes by the
    scalar rules: the test above then compares real cases, and the contacts equal those built
    by the rules on arrays."""
    taken = 0
    for dim, model in ((2, "point"), (2, "pad"), (2, "frictionless"), (3, "point"), (3, "soft"), (2, "patch")):
        if dim not in registry.get(model).dims:
            continue
        for g in random_grasps(5, 40, dim=dim, model=model):
            for c in g.contacts:
                for n in (c.n, tuple(2.5 * x for x in c.n)):
                    value = {"p": c.p, "n": n, "model": c.model, **dict(c.params)}
                    fast, ref = check_contact(value), _reference_contact(value)
                    assert fast is not None, value
                    assert _bits(fast[0]) == _bits(ref[0]) and _bits(fast[1]) == _bits(ref[1])
                    taken += 1
    assert taken > 1000


def _reference_geometry(contacts, center, length):
    data = GraspData(np.array([len(contacts)]), np.zeros((1, 3)), np.full(1, -1), np.full(1, np.nan),
                     np.zeros(1, dtype=bool), [None], [None], [{}])
    if center is not None:
        data.center[0, : len(center)], data.clen[0] = center, len(center)
    if length is not None:
        data.length[0], data.length_given[0] = length, True
    checked = grasp_rules(data, _checked_of(contacts))
    if checked.error[0] is not None:
        return None
    dim = int(checked.dim[0])
    return checked.center[0, :dim], checked.length[0]


_COORD = st.one_of(st.floats(-5, 5), st.sampled_from([0.0, -0.0, 1e-300, 1e-20, 1e6, -1e6]))


@settings(max_examples=500, deadline=None, suppress_health_check=list(HealthCheck))
@given(points=st.integers(2, 3).flatmap(lambda d: st.lists(st.tuples(*[_COORD] * d), min_size=1, max_size=6)),
       center=st.one_of(st.none(), st.lists(_COORD, min_size=2, max_size=3), st.just([float("nan"), 0.0])),
       length=st.one_of(st.none(), st.floats(0, 10), st.sampled_from([0.0, 1e-20, 1e-9, 4e6, 4e6 + 1]),
                        st.just(float("inf"))),
       copies=st.integers(1, 3))
def test_one_grasps_rules_give_the_array_rules_center_and_length_bit_for_bit(points, center, length, copies):
    contacts = tuple(Contact(q, (1.0,) + (0.0,) * (len(q) - 1)) for q in points) * copies
    fast = grasp_geometry([c.p for c in contacts], center, length)
    ref = _reference_geometry(contacts, center, length)
    assert (fast is None) == (ref is None), (points, center, length)
    if fast is not None:
        assert _bits(fast[0]) == _bits(ref[0]) and float(fast[1]).hex() == float(ref[1]).hex()


def test_the_scalar_rules_read_values_in_the_order_of_the_array_rules():
    """A value whose conversion raises is read only where the rules on arrays read it: ``n`` after
    a valid ``p`` (a review found ``n`` read first), the parameters after both."""
    bad = np.timedelta64(1, "s")  # an np.number whose float() raises
    for p, message in ((None, "p: missing"), ([1.0], "p: expected 2"), ("ab", "p: expected 2")):
        with pytest.raises(GraspError, match=message):
            Contact(p, [bad, 0.0])
    with pytest.raises(TypeError):
        Contact([0.0, 1.0], [bad, 0.0])


def _special_floats(rng, shape):
    """Floats of every scale with zeros, signed zeros, subnormals, infinities and NaN mixed in."""
    x = rng.standard_normal(shape) * np.exp(rng.uniform(-40, 40, shape))
    specials = np.array([0.0, -0.0, 5e-324, 1e-160, 1e154, 1e6, np.inf, -np.inf, np.nan, 1.0, -1.0])
    pick = rng.random(shape) < 0.15
    x[pick] = rng.choice(specials, int(pick.sum()))
    return x


def _reference_normals(n):
    """The normals and lengths of the validation's rules written with numpy's row reductions (the
    columns' loops must give the same floats)."""
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        scale = np.abs(n).max(axis=1)
        safe = np.where(scale > 0, scale, 1.0)
        norm = safe * np.sqrt(((n / safe[:, None]) ** 2).sum(axis=1))
        unit = np.abs(norm - 1.0) <= 1e-12
        plain = np.sqrt((n * n).sum(axis=1))
        norm = np.where(np.isfinite(plain) & (plain > 1e-150), plain, norm)
        return np.where(unit[:, None], n, n / np.where(norm > 0, norm, 1.0)[:, None]), norm


@pytest.mark.parametrize("dim", [2, 3])
def test_the_rules_on_arrays_give_the_row_reductions_values_bit_for_bit(dim):
    """Normals, errors and default lengths of 30,000 contacts of every scale (unit ones too) equal
    those of numpy's row reductions (``max``, ``sum``, ``all`` along a row), which the rules
    compute column by column for speed."""
    rng = np.random.default_rng(dim)
    k = 30_000
    p, n = _special_floats(rng, (k, dim)), _special_floats(rng, (k, dim))
    unit = rng.random(k) < 0.3
    n[unit] = rng.standard_normal((int(unit.sum()), dim))
    n[unit] /= np.linalg.norm(n[unit], axis=1)[:, None]
    checked = check_contacts(contact_arrays(p, n, "frictionless"))
    n3 = np.zeros((k, 3))
    n3[:, :dim] = np.where(np.isfinite(n), n, 0.0)
    stored, norm = _reference_normals(n3)
    with np.errstate(invalid="ignore"):
        valid = ((np.abs(p) <= MAX_LENGTH).all(axis=1) & np.isfinite(n).all(axis=1) & (norm >= MIN_NORMAL))
    assert np.array_equal(checked.error == None, valid)  # noqa: E711
    assert 0.2 * k < valid.sum() < 0.9 * k
    assert checked.n[valid].tobytes() == stored[valid].tobytes()
    # grasps of 1 to 5 of the valid contacts: default center and length as the row reductions give them
    P = np.where(np.isfinite(p), p, 0.0)[valid]
    P[np.abs(P) > 1e6] = 1e6
    count = rng.integers(1, 6, len(P) // 3)
    count = count[np.cumsum(count) <= len(P)]
    P = P[: count.sum()]
    data = GraspData(count, np.zeros((len(count), 3)), np.full(len(count), -1), np.full(len(count), np.nan),
                     np.zeros(len(count), bool), [None] * len(count), [None] * len(count), [{}] * len(count))
    normal = np.zeros((len(P), dim))
    normal[:, 0] = 1.0
    grasps = grasp_rules(data, check_contacts(contact_arrays(P, normal, "frictionless")))
    offsets = np.concatenate([[0], np.cumsum(count)])
    ok = grasps.error == None  # noqa: E711
    assert ok.mean() > 0.5
    for i in np.flatnonzero(ok)[:3000]:
        q = np.zeros((count[i], 3))
        q[:, :dim] = P[offsets[i]:offsets[i + 1]]
        c = grasps.center[i]
        d = q - c
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            scale = np.abs(d).max(axis=1)
            far = (scale * np.sqrt(((d / np.where(scale > 0, scale, 1.0)[:, None]) ** 2).sum(axis=1))).max()
        size = np.nan_to_num(np.abs(q)).max()
        assert grasps.length[i] == (far if far > 8 * 2.0**-53 * size else 1.0)


def test_grasps_mixing_dimensions_and_empty_grasps_anywhere_get_their_own_errors():
    """The dimension check reduces over each grasp's consecutive contacts: grasps without
    contacts (first, last, in between) and mixed ones among valid ones each get their own error."""
    rng = np.random.default_rng(4)
    contact = {2: {"p": [0.0, 0.0], "n": [1.0, 0.0]}, 3: {"p": [0.0, 0.0, 0.0], "n": [1.0, 0.0, 0.0]}}
    dims = [[], [2, 2]] + [list(rng.choice([2, 3], rng.integers(0, 5))) for _ in range(2000)] + [[3, 2], []]
    cols = value_columns([{"contacts": [contact[int(d)] for d in ds]} for ds in dims])
    for ds, error in zip(dims, cols.checked.error):
        if not ds:
            assert error == "contacts: a grasp needs at least one contact"
        elif len(set(ds)) > 1:
            assert error == "contacts: mix dimensions [2, 3]; a grasp is planar or spatial"
        else:
            assert error is None
