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
