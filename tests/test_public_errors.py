"""Only promised errors escape the public API.

Every function and class that ``qualgrasp`` and ``qualgrasp.certify`` export (the names in their
``__all__``), fed bad arguments, raises what :mod:`qualgrasp.certify.errors` promises: a
:class:`qualgrasp.QualgraspError` for a value of the right type outside the function's domain
(NaN, empty, wrongly shaped, an unknown method, norm or model, an option that does not apply),
``TypeError`` (or a :class:`~qualgrasp.QualgraspError`) for a plainly wrong Python type; never an
``AttributeError``, ``IndexError`` or a bare ``ValueError`` from deep inside. Every exception class
of the package derives from :class:`~qualgrasp.QualgraspError` and is exported from ``qualgrasp``.
"""

from __future__ import annotations

import importlib
import inspect
import math
import pkgutil

import numpy as np
import pytest

import qualgrasp as qg
from qualgrasp import certify as qc

G = qg.Grasp((qg.Contact((1, 0), (-1, 0), "point", 0.5), qg.Contact((-1, 0), (1, 0), "point", 0.5)))
PAD = qg.Grasp((qg.Contact((1, 0), (-1, 0), "pad", mu=0.5, width=0.1),
                qg.Contact((-1, 0), (1, 0), "pad", mu=0.5, width=0.1)))
V = qg.force_closure(G)
NAN = math.nan

VALUE, TYPE = "value", "type"

#: ``{public name: [(what is wrong, call, kind)]}``; kind VALUE: a QualgraspError must escape,
#: TYPE: TypeError or a QualgraspError.
BAD = {
    "Contact": [
        ("NaN point", lambda: qg.Contact((NAN, 0), (1, 0)), VALUE),
        ("empty point", lambda: qg.Contact((), ()), VALUE),
        ("four coordinates", lambda: qg.Contact((1, 2, 3, 4), (1, 0, 0, 0)), VALUE),
        ("zero normal", lambda: qg.Contact((1, 0), (0, 0)), VALUE),
        ("unknown model", lambda: qg.Contact((1, 0), (1, 0), "glue"), VALUE),
        ("negative friction", lambda: qg.Contact((1, 0), (1, 0), "point", -0.5), VALUE),
        ("NaN friction", lambda: qg.Contact((1, 0), (1, 0), "point", NAN), VALUE),
        ("a string for the point", lambda: qg.Contact("ab", (1, 0)), TYPE),
        ("None for the point", lambda: qg.Contact(None, (1, 0)), TYPE),
    ],
    "Grasp": [
        ("no contacts", lambda: qg.Grasp(()), VALUE),
        ("planar and spatial contacts", lambda: qg.Grasp((qg.Contact((1, 0), (1, 0)),
                                                          qg.Contact((1, 0, 0), (1, 0, 0)))), VALUE),
        ("NaN length", lambda: qg.Grasp(G.contacts, length=NAN), VALUE),
        ("centre of the wrong dimension", lambda: qg.Grasp(G.contacts, center=(1, 2, 3)), VALUE),
        ("numbers for contacts", lambda: qg.Grasp((1, 2)), TYPE),
        ("None for contacts", lambda: qg.Grasp(None), TYPE),
    ],
    "grasp_from_dict": [
        ("no contacts", lambda: qg.grasp_from_dict({}), VALUE),
        ("empty contacts", lambda: qg.grasp_from_dict({"contacts": []}), VALUE),
        ("NaN point", lambda: qg.grasp_from_dict({"contacts": [{"p": [NAN, 0], "n": [1, 0]}]}), VALUE),
        ("a string", lambda: qg.grasp_from_dict("x"), TYPE),
        ("None", lambda: qg.grasp_from_dict(None), TYPE),
    ],
    "grasp_to_dict": [
        ("a number", lambda: qg.grasp_to_dict(42), TYPE),
        ("None", lambda: qg.grasp_to_dict(None), TYPE),
    ],
    "force_closure": [
        ("socp with pads (no conic form)", lambda: qg.force_closure(PAD, socp=True), VALUE),
        ("unknown method", lambda: qg.force_closure(G, method="nope"), VALUE),
        ("a number for the grasp", lambda: qg.force_closure(42), TYPE),
        ("a string for the tolerances", lambda: qg.force_closure(G, tol="x"), TYPE),
    ],
    "form_closure": [
        ("unknown method", lambda: qg.form_closure(G, method="nope"), VALUE),
        ("a number for the grasp", lambda: qg.form_closure(42), TYPE),
    ],
    "positive_span": [
        ("no vectors", lambda: qg.positive_span([]), VALUE),
        ("NaN", lambda: qg.positive_span([[NAN, 0], [1, 0]]), VALUE),
        ("ragged rows", lambda: qg.positive_span([[1, 2], [3]]), VALUE),
        ("unknown method", lambda: qg.positive_span([[1, 0], [-1, 0]], method="nope"), VALUE),
        ("a string", lambda: qg.positive_span("abc"), TYPE),
    ],
    "verify": [
        ("None for the certificate", lambda: qg.verify(G, None), TYPE),
        ("a dict for the certificate", lambda: qg.verify(G, {"kind": "interior"}), TYPE),
        ("a number for the grasp", lambda: qg.verify(42, V.certificate), TYPE),
    ],
    "verify_span": [
        ("no vectors", lambda: qc.verify_span([], V.certificate), VALUE),
        ("NaN", lambda: qc.verify_span([[NAN, 0], [1, 0]], V.certificate), VALUE),
        ("None for the certificate", lambda: qc.verify_span([[1, 0], [-1, 0]], None), TYPE),
    ],
    "certify_grasp": [
        ("unknown method", lambda: qg.certify_grasp(G, method="nope"), VALUE),
        ("a number for the grasp", lambda: qg.certify_grasp(42), TYPE),
    ],
    "epsilon": [
        ("unknown norm", lambda: qg.epsilon(G, "L3"), VALUE),
        ("NaN relative gap", lambda: qg.epsilon(G, rel_gap=NAN), VALUE),
        ("negative budget", lambda: qg.epsilon(G, budget=-1), VALUE),
        ("a number for the grasp", lambda: qg.epsilon(42), TYPE),
    ],
    "synthesize": [
        ("no such image", lambda: qg.synthesize("/nonexistent/image.png", 2), VALUE),
        ("no fingers", lambda: qg.synthesize(np.zeros((10, 10)), 0), VALUE),
        ("None for the image", lambda: qg.synthesize(None, 2), TYPE),
    ],
    "certify_arrow": [
        ("a string for the data", lambda: qc.certify_arrow("nonsense"), TYPE),
        ("None for the data", lambda: qc.certify_arrow(None), TYPE),
        ("a string for the options", lambda: qc.certify_arrow([], options="x"), TYPE),
    ],
    "Options": [
        ("unknown method", lambda: qc.Options(method="nope"), VALUE),
        ("NaN epsilon gap", lambda: qc.Options(eps_gap=NAN), VALUE),
        ("no epsilon budget", lambda: qc.Options(eps_budget=0), VALUE),
        ("negative time limit", lambda: qc.Options(eps_time=-1.0), VALUE),
    ],
    "Tolerances": [
        ("negative", lambda: qc.Tolerances(rank=-1.0), VALUE),
        ("NaN", lambda: qc.Tolerances(margin=NAN), VALUE),
    ],
    "Certificate": [
        ("not an object", lambda: qc.Certificate.from_json("garbage"), VALUE),
        ("unknown kind", lambda: qc.Certificate.from_json({"kind": "maybe", "layout": "columns"}), VALUE),
    ],
}

#: Records the functions return: their constructors take what the functions give them and are not
#: an input route (a :class:`~qualgrasp.certify.Certificate` is read with ``from_json``, above).
RECORDS = {"Verdict", "Check", "Report", "Epsilon", "Synthesis"}


def _public(module) -> list[str]:
    return [n for n in module.__all__ if not (inspect.isclass(getattr(module, n))
                                              and issubclass(getattr(module, n), BaseException))]


def test_every_public_name_is_fed_bad_arguments():
    names = set(_public(qg)) | set(_public(qc))
    assert names - RECORDS == set(BAD), "add bad-argument cases for the new public names"
    assert RECORDS <= names


CASES = [pytest.param(call, kind, id=f"{name}: {what}") for name, cases in BAD.items()
         for what, call, kind in cases]


@pytest.mark.parametrize("call, kind", CASES)
def test_only_promised_errors_escape(call, kind):
    with pytest.raises(Exception) as info:
        call()
    err = info.value
    allowed = (qg.QualgraspError,) if kind == VALUE else (qg.QualgraspError, TypeError)
    assert isinstance(err, allowed), f"{type(err).__name__}: {err}"
    assert str(err) and "\n" not in str(err), "one line naming the problem"


def _exception_classes():
    found = {}
    for info in pkgutil.walk_packages(qg.__path__, "qualgrasp."):
        if any(p.startswith("_") for p in info.name.split(".")):
            continue
        module = importlib.import_module(info.name)
        for name, obj in vars(module).items():
            if (inspect.isclass(obj) and issubclass(obj, BaseException) and not name.startswith("_")
                    and obj.__module__.startswith("qualgrasp")):
                found[name] = obj
    return found


def test_one_root_exception_and_every_exception_is_exported():
    classes = _exception_classes()
    assert len(classes) >= 20
    for name, cls in classes.items():
        assert issubclass(cls, qg.QualgraspError), name
        assert getattr(qg, name, None) is cls and name in qg.__all__, f"qualgrasp does not export {name}"
    assert issubclass(qg.QualitativeError, qg.QualgraspError) and issubclass(qg.CertifyError, qg.QualgraspError)


def test_literal_types_name_what_is_validated():
    from typing import get_args

    from qualgrasp.certify import models
    from qualgrasp.certify.quality import NORMS, epsilon
    from qualgrasp.certify.solvers import METHODS, make_solver

    assert set(get_args(models.ModelName)) == set(models.names())
    for name in get_args(models.ModelName):
        params = {"point": {"mu": 0.5}, "soft": {"mu": 0.5, "torsion": 0.1}, "pad": {"mu": 0.5, "width": 0.1},
                  "patch": {"mu": 0.5, "radius": 0.1}}
        p, n = ((1, 0, 0), (-1, 0, 0)) if name in ("soft", "patch") else ((1, 0), (-1, 0))
        assert qg.Contact(p, n, name, **params.get(name, {})).model == name
    for method in METHODS:
        assert make_solver(method) is not None
    for norm in NORMS:
        assert epsilon(G, norm).hi > 0
