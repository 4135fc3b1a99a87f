"""ST0: parsing, the fast evaluator against the naive one and the temporal identities, traces."""

import json

import numpy as np
import pytest
import typer
from hypothesis import given, strategies as st
from typer.testing import CliRunner

from qualgrasp.qualitative.cli import st0_command
from qualgrasp.qualitative.errors import FormulaError, TraceError
from qualgrasp.qualitative.reasoning.rcc8 import RELATIONS
from qualgrasp.qualitative.reasoning.st0 import (Always, And, Atom, Const, Historically, Implies, Next, Not, Once, Or,
                                                 Previous, Since, Sometime, Until, evaluate_file, parse, read_trace,
                                                 write_trace)
from st0_reference import evaluate_reference

CONV = {"DC": "DC", "EC": "EC", "PO": "PO", "EQ": "EQ",
        "TPP": "TPPi", "TPPi": "TPP", "NTPP": "NTPPi", "NTPPi": "NTPP"}
PAIRS = [("A", "B"), ("B", "A"), ("B", "C"), ("C", "B"), ("A", "C"), ("C", "A"), ("A", "A")]
TRUE = Const(True)


# ------------------------------------------------------------------------- strategies

@st.composite
def traces(draw, min_size=1, max_size=12):
    """Frames over A, B, C; each pair stored one way or the other (or both, consistently)."""
    frames = []
    for _ in range(draw(st.integers(min_size, max_size))):
        frame = {}
        for x, y in (("A", "B"), ("B", "C"), ("A", "C")):
            r = draw(st.sampled_from(RELATIONS))
            how = draw(st.sampled_from(["forward", "backward", "both"]))
            if how != "backward":
                frame[(x, y)] = r
            if how != "forward":
                frame[(y, x)] = CONV[r]
        frames.append(frame)
    return frames


atoms = st.builds(lambda rels, pair: Atom(frozenset(rels), *pair),
                  st.sets(st.sampled_from(RELATIONS), min_size=1, max_size=3), st.sampled_from(PAIRS))
leaves = st.one_of(atoms, atoms, st.builds(Const, st.booleans()))
formulas = st.recursive(leaves, lambda kids: st.one_of(
    *(st.builds(op, kids) for op in (Not, Next, Sometime, Always, Previous, Once, Historically)),
    *(st.builds(op, kids, kids) for op in (Implies, Until, Since)),
    st.builds(lambda a, b: And((a, b)), kids, kids),
    st.builds(lambda a, b, c: Or((a, b, c)), kids, kids, kids),
), max_leaves=8)


# ---------------------------------------------------------------------------- semantics

@given(formulas, traces(min_size=0))
def test_fast_evaluator_agrees_with_the_naive_per_instant_one(f, trace):
    assert np.array_equal(f.evaluate(trace), evaluate_reference(f, trace))


# p = EC(A,B) holds at instants 0, 2, 3 of five; q = DC(A,B) at 1 and 4
_HAND_TRACE = [{("A", "B"): r} for r in ("EC", "DC", "EC", "EC", "DC")]
_P, _Q = Atom(frozenset({"EC"}), "A", "B"), Atom(frozenset({"DC"}), "A", "B")


@pytest.mark.parametrize("formula, expected", [
    (_P, [1, 0, 1, 1, 0]),
    (Next(_P), [0, 1, 1, 0, 0]),            # false at the last instant
    (Previous(_P), [0, 1, 0, 1, 1]),        # false at instant 0
    (Sometime(_Q), [1, 1, 1, 1, 1]),
    (Always(_P), [0, 0, 0, 0, 0]),
    (Once(_Q), [0, 1, 1, 1, 1]),
    (Historically(_P), [1, 0, 0, 0, 0]),
    (Until(_P, _Q), [1, 1, 1, 1, 1]),       # p holds up to each next q
    (Until(_Q, _P), [1, 1, 1, 1, 0]),       # no p from instant 4 on
    (Since(_P, _Q), [0, 1, 1, 1, 1]),       # no q at or before instant 0
    (Since(_Q, _P), [1, 1, 1, 1, 1]),
    (Implies(_P, Next(_P)), [0, 1, 1, 0, 1]),
])
def test_each_operator_on_a_trace_worked_by_hand(formula, expected):
    """Both evaluators against values worked out by hand (the property test above would accept
    a fault the two shared)."""
    assert formula.evaluate(_HAND_TRACE).astype(int).tolist() == expected
    assert np.asarray(evaluate_reference(formula, _HAND_TRACE)).astype(int).tolist() == expected


@given(formulas, traces())
def test_sometime_always_and_their_past_duals(p, trace):
    ev = lambda f: f.evaluate(trace)
    assert np.array_equal(ev(Sometime(p)), ev(Until(TRUE, p)))
    assert np.array_equal(ev(Always(p)), ev(Not(Sometime(Not(p)))))
    assert np.array_equal(ev(Once(p)), ev(Since(TRUE, p)))
    assert np.array_equal(ev(Historically(p)), ev(Not(Once(Not(p)))))


@given(formulas, formulas, traces())
def test_until_and_since_unfold_one_step(p, q, trace):
    ev = lambda f: f.evaluate(trace)
    assert np.array_equal(ev(Until(p, q)), ev(Or((q, And((p, Next(Until(p, q))))))))
    assert np.array_equal(ev(Since(p, q)), ev(Or((q, And((p, Previous(Since(p, q))))))))


@given(formulas, traces())
def test_strong_next_and_previous_at_the_ends(p, trace):
    p_values = p.evaluate(trace)
    assert not Next(p).evaluate(trace)[-1]
    assert not Previous(p).evaluate(trace)[0]
    assert np.array_equal(Next(p).evaluate(trace)[:-1], p_values[1:])
    assert np.array_equal(Previous(Next(p)).evaluate(trace)[1:], p_values[1:])


def test_hand_computed_trace():
    trace = [{("A", "B"): "DC"}, {("B", "A"): "EC"}, {("A", "B"): "PO"}, {("B", "A"): "TPPi"}]
    ev = lambda text: parse(text).evaluate(trace).tolist()
    assert ev("EC(A,B)") == [False, True, False, False]
    assert ev("TPP(A,B)") == [False, False, False, True]        # read from the converse
    assert ev("{DC,EC}(A,B) U PO(A,B)") == [True, True, True, False]
    assert ev("DC(A,B) U PO(A,B)") == [False, False, True, False]
    assert ev("X EC(A,B)") == [True, False, False, False]
    assert ev("Y EC(A,B)") == [False, False, True, False]
    assert ev("!PO(A,B) S DC(A,B)") == [True, True, False, False]
    assert ev("EC(A,B) S DC(A,B)") == [True, True, False, False]   # q where p fails counts
    assert ev("PO(A,B) U EC(A,B)") == [False, True, False, False]
    assert ev("G F TPPi(B,A)") == [True] * 4
    assert ev("F TPP(B,A)") == [False] * 4
    assert ev("EQ(A,A) & !DC(B,B)") == [True] * 4
    assert parse("EC(A,B)").holds(trace) is False
    assert parse("F PO(A,B)").holds(trace) is True


def test_empty_trace():
    assert parse("G EC(A,B)").evaluate([]).shape == (0,)
    with pytest.raises(TraceError, match="empty"):
        parse("true").holds([])


# ------------------------------------------------------------------------------ parsing

A, B = Atom(frozenset({"EC"}), "A", "B"), Atom(frozenset({"DC"}), "B", "C")
C = Atom(frozenset({"PO"}), "A", "C")


@pytest.mark.parametrize("text, tree", [
    ("!EC(A,B) U DC(B,C)", Until(Not(A), B)),
    ("EC(A,B) & DC(B,C) | PO(A,C)", Or((And((A, B)), C))),
    ("EC(A,B) | DC(B,C) & PO(A,C)", Or((A, And((B, C))))),
    ("EC(A,B) -> DC(B,C) -> PO(A,C)", Implies(A, Implies(B, C))),
    ("EC(A,B) U DC(B,C) U PO(A,C)", Until(A, Until(B, C))),
    ("EC(A,B) U DC(B,C) S PO(A,C)", Until(A, Since(B, C))),
    ("EC(A,B) & DC(B,C) U PO(A,C)", And((A, Until(B, C)))),
    ("G EC(A,B) -> DC(B,C)", Implies(Always(A), B)),
    ("X Y O H F G !EC(A,B)", Next(Previous(Once(Historically(Sometime(Always(Not(A)))))))),
    ("GF EC(A,B)", Always(Sometime(A))),
    ("XEC(A,B)", Next(A)),
    ("(EC(A,B) | DC(B,C)) & PO(A,C)", And((Or((A, B)), C))),
    ("{PO,EC,PO}( A , B )", Atom(frozenset({"EC", "PO"}), "A", "B")),
    ("true & !false", And((Const(True), Not(Const(False))))),
    # operator letters are region names inside an atom
    ("G(EC(F2,O) -> O(EC(F1,O)))", Always(Implies(Atom(frozenset({"EC"}), "F2", "O"),
                                                  Once(Atom(frozenset({"EC"}), "F1", "O"))))),
    ("EC(X,Y) U PO(U,S)", Until(Atom(frozenset({"EC"}), "X", "Y"), Atom(frozenset({"PO"}), "U", "S"))),
])
def test_precedence_and_associativity(text, tree):
    assert parse(text) == tree


@given(formulas)
def test_printed_formulas_parse_back(f):
    assert parse(str(f)) == f


@pytest.mark.parametrize("text, column, expected", [
    ("EC(A,B) &", 10, "a formula"),
    ("EC(A,)", 6, "a region name"),
    ("EC(A B)", 6, "','"),
    ("EC A,B)", 4, "'('"),
    ("tpp(A,B)", 1, "did you mean TPP"),
    ("{DC,XX}(A,B)", 5, "a relation name"),
    ("{DC EC}(A,B)", 5, "'}'"),
    ("(EC(A,B)", 9, "')' closing the '(' at column 1"),
    ("EC(A,B) EC(B,C)", 9, "an operator"),
    ("U EC(A,B)", 1, "before the binary operator U"),
    ("EC(A,B) # DC(A,B)", 9, "an operator"),
    ("", 1, "a formula"),
])
def test_parse_errors_give_the_column_and_what_was_expected(text, column, expected):
    with pytest.raises(FormulaError) as info:
        parse(text)
    assert info.value.column == column
    assert expected in info.value.expected
    assert f"column {column}" in str(info.value)


# -------------------------------------------------------------------------------- traces

def test_trace_errors_name_the_problem():
    with pytest.raises(TraceError, match=r"frame 1 gives no relation for the pair \('A', 'C'\)"):
        parse("EC(A,C)").evaluate([{("A", "C"): "EC"}, {("A", "B"): "EC"}])
    with pytest.raises(TraceError, match="frame 0, pair.*unknown relation 'XX'"):
        parse("EC(A,B)").evaluate([{("B", "A"): "XX"}])
    with pytest.raises(TraceError, match="frame 1 is a list"):
        parse("EC(A,B)").evaluate([{("A", "B"): "EC"}, ["EC"]])
    with pytest.raises(TraceError, match="not its converse"):
        parse("EC(A,B)").evaluate([{("A", "B"): "TPP", ("B", "A"): "TPP"}])
    with pytest.raises(TraceError, match="sequence"):
        parse("EC(A,B)").evaluate({("A", "B"): "EC"})


def test_trace_files_round_trip(tmp_path):
    trace = [{("A", "B"): "DC", ("B", "C"): "TPP"}, {("B", "A"): "EC", ("C", "B"): "NTPPi"}]
    path = tmp_path / "trace.json"
    write_trace(trace, path)
    assert read_trace(path) == trace
    assert json.loads(path.read_text())[0] == {"A,B": "DC", "B,C": "TPP"}
    assert evaluate_file("EC(A,B) | NTPP(B,C)", path).tolist() == [False, True]


@pytest.mark.parametrize("content, message", [
    ("[{\"A,B\": \"DC\"", "not valid JSON"),
    ("{\"A,B\": \"DC\"}", "expected a JSON list"),
    ("[[\"A,B\", \"DC\"]]", "frame 0: expected an object"),
    ("[{\"A,B\": \"DC\"}, {\"AB\": \"DC\"}]", "frame 1: key 'AB' is not two region names"),
    ("[{\"A,B,C\": \"DC\"}]", "not two region names"),
    ("[{\"A,B\": \"dc\"}]", "unknown relation 'dc'"),
    ("[{\"A,B\": 3}]", "unknown relation 3"),
    ("[{\"A,B\": \"DC\", \" A , B\": \"EC\"}]", "given twice"),
])
def test_malformed_trace_files(tmp_path, content, message):
    path = tmp_path / "bad.json"
    path.write_text(content)
    with pytest.raises(TraceError, match=message):
        read_trace(path)


def test_missing_trace_file(tmp_path):
    with pytest.raises(TraceError, match="cannot read"):
        evaluate_file("true", tmp_path / "nope.json")


# ----------------------------------------------------------------------------------- CLI

def _app():
    app = typer.Typer()
    app.command("st0")(st0_command)
    app.callback()(lambda: None)  # keep "st0" a subcommand
    return app


def test_st0_command_prints_one_line_per_instant(tmp_path):
    path = tmp_path / "trace.json"
    write_trace([{("A", "B"): "DC"}, {("A", "B"): "EC"}, {("A", "B"): "PO"}], path)
    result = CliRunner().invoke(_app(), ["st0", "DC(A,B) U PO(A,B)", "--trace", str(path)])
    assert result.exit_code == 0, result.output
    assert result.stdout.splitlines() == ["0\tfalse", "1\tfalse", "2\ttrue"]


@pytest.mark.parametrize("formula, content, message", [
    ("EC(A,B", '[{"A,B": "DC"}]', "column 7"),
    ("EC(A,B)", '[{"A,B": "XX"}]', "unknown relation 'XX'"),
    ("EC(A,C)", '[{"A,B": "DC"}]', "no relation for the pair"),
])
def test_st0_command_exit_code_2_on_bad_input(tmp_path, formula, content, message):
    path = tmp_path / "trace.json"
    path.write_text(content)
    result = CliRunner().invoke(_app(), ["st0", formula, "--trace", str(path)])
    assert result.exit_code == 2
    assert message in result.stderr


# ------------------------------------------------------------------- limits (what they measure)

from qualgrasp.qualitative.reasoning import st0 as st0_module  # noqa: E402
from qualgrasp.qualitative.reasoning.st0 import MAX_DEPTH  # noqa: E402


def _chain(kind: str, levels: int) -> str:
    """A formula nesting ``levels`` of one kind of operator (or bracket) inside each other."""
    atom = "EC(A,B)"
    if kind == "brackets":
        return "(" * levels + atom + ")" * levels
    if kind == "not":
        return "!" * levels + atom
    if kind == "next":
        return "X " * levels + atom
    if kind == "word":                      # XXX...EC(A,B): one word, read letter by letter
        return "X" * levels + atom
    if kind in ("->", "U", "S"):            # right-associative chains
        return f" {kind} ".join([atom] * (levels + 1))
    if kind == "and-or":                    # (a | (a & (a | ...))): & and | each count
        text = atom
        for i in range(levels // 2):
            text = f"(DC(A,B) | EC(A,B) & {text})"
        return text if levels % 2 == 0 else f"!{text}"
    raise ValueError(kind)


@pytest.mark.parametrize("kind", ["not", "next", "word", "->", "U", "S", "and-or"])
def test_operator_nesting_at_the_limit_parses_and_past_it_is_refused(kind):
    at = parse(_chain(kind, MAX_DEPTH))
    assert at.depth() == MAX_DEPTH
    trace = [{("A", "B"): "EC"}] * 3
    assert at.evaluate(trace).shape == (3,)           # evaluation recurses per level
    assert parse(str(at)) == at                       # and so does printing
    with pytest.raises(FormulaError, match=f"nests more than {MAX_DEPTH} operators"):
        parse(_chain(kind, MAX_DEPTH + 1))


def test_bracket_nesting_at_the_limit_parses_and_past_it_is_refused():
    assert parse(_chain("brackets", MAX_DEPTH)).depth() == 0
    with pytest.raises(FormulaError, match=f"nests more than {MAX_DEPTH} brackets"):
        parse(_chain("brackets", MAX_DEPTH + 1))


def test_siblings_do_not_count_as_nesting():
    """101 bracketed atoms side by side nest one deep: the limit caps nesting, not the number of
    operators (the depth counter used never to go down)."""
    for sep in (" & ", " | "):
        f = parse(sep.join(["(EC(A,B))"] * (MAX_DEPTH + 1)))
        assert f.depth() == 1
    f = parse(" & ".join(["!X(EC(A,B) U DC(A,B))"] * 200))
    assert f.depth() == 4


deep_formulas = st.recursive(leaves, lambda kids: st.one_of(
    *(st.builds(op, kids) for op in (Not, Next, Sometime, Always, Previous, Once, Historically)),
    *(st.builds(op, kids, kids) for op in (Implies, Until, Since)),
    st.builds(lambda a, b: And((a, b)), kids, kids),
    st.builds(lambda a, b: Or((a, b)), kids, kids),
), max_leaves=400)


def _wrap_to_depth(f, depth, ops):
    for op in ops[:max(0, depth - f.depth())]:
        f = op(f) if op in (Not, Next, Sometime, Always, Previous, Once, Historically) else op(f, A)
    return f


@given(deep_formulas, st.lists(st.sampled_from([Not, Next, Always, Until, Since, Implies]),
                               min_size=MAX_DEPTH, max_size=MAX_DEPTH))
def test_every_formula_within_the_depth_limit_prints_and_parses_back(f, ops):
    """Generated valid formulas: whatever their shape, those at most MAX_DEPTH deep parse back
    (13 of 12,000 used to be refused), one level more is refused."""
    f = _wrap_to_depth(f, MAX_DEPTH, ops) if f.depth() <= MAX_DEPTH else f
    if f.depth() > MAX_DEPTH:
        with pytest.raises(FormulaError):
            parse(str(f))
        return
    assert parse(str(f)) == f
    deeper = Not(f) if f.depth() == MAX_DEPTH else _wrap_to_depth(f, MAX_DEPTH + 1, [Not] * (MAX_DEPTH + 1))
    with pytest.raises(FormulaError, match="nests more than"):
        parse(str(deeper))


def test_formula_length_at_the_limit_and_past_it():
    text = " & ".join(["EC(A,B)"] * 1000)
    text = text[:st0_module.MAX_FORMULA - len(" & true")].rsplit(" & ", 1)[0]
    text = text + " " * (st0_module.MAX_FORMULA - len(text) - len(" & true")) + " & true"
    assert len(text) == st0_module.MAX_FORMULA
    parse(text)
    with pytest.raises(FormulaError, match="characters"):
        parse(text + " ")


def test_formulas_built_in_code_deeper_than_the_limit_are_refused_not_a_recursion_error():
    f = Const(True)
    for _ in range(5 * MAX_DEPTH):
        f = Not(f)
    with pytest.raises(FormulaError, match="nests more than"):
        f.evaluate([{("A", "B"): "EC"}])


def test_trace_size_limit_counts_bytes(tmp_path, monkeypatch):
    frame = '{"A,B": "EC"}'
    text = "[" + ", ".join([frame] * 50) + "]"
    monkeypatch.setattr(st0_module, "MAX_TRACE_BYTES", len(text.encode()))
    path = tmp_path / "t.json"
    path.write_text(text)
    assert len(read_trace(path)) == 50
    path.write_text(text + " ")
    with pytest.raises(TraceError, match="larger than"):
        read_trace(path)


def _arrangements(k: int, regions: int = 3) -> list[dict]:
    """Frames of ``k`` different arrangements (chains of ``regions`` regions, all consistent),
    each repeated under other region names (which must not count again)."""
    frames = []
    for code in range(k):
        rels = [("NTPP", "EQ", "TPP")[(code // 3 ** i) % 3] for i in range(regions - 1)]
        for prefix in ("R", "S"):
            frames.append({f"{prefix}{i},{prefix}{i + 1}": r for i, r in enumerate(rels)})
    return frames


def test_trace_arrangement_work_at_the_limit_and_past_it(tmp_path, monkeypatch):
    """The consistency checks' work is bounded before it is done: each different arrangement
    costs 1 + regions squared, frames equal up to their regions' names share one check."""
    per = 1 + 4 ** 2
    monkeypatch.setattr(st0_module, "MAX_ARRANGEMENT_WORK", 20 * per)
    path = tmp_path / "t.json"
    path.write_text(json.dumps(_arrangements(20, regions=4) * 3))
    assert len(read_trace(path)) == 120
    path.write_text(json.dumps(_arrangements(21, regions=4)))
    with pytest.raises(TraceError, match="arrangements"):
        read_trace(path)


def test_frames_read_once_are_still_separate_frames(tmp_path):
    path = tmp_path / "t.json"
    path.write_text(json.dumps([{"A,B": "EC"}] * 3 + [{"A,B": "DC"}]))
    trace = read_trace(path)
    trace[0][("A", "C")] = "DC"
    assert trace[1] == {("A", "B"): "EC"} and trace[3] == {("A", "B"): "DC"}


def test_evaluation_work_at_the_limit_and_past_it(monkeypatch):
    f = parse("EC(A,B) U DC(B,C)")               # 2 pairs, 3 nodes: 23 units per frame
    trace = [{("A", "B"): "EC", ("B", "C"): "DC"}] * 10
    monkeypatch.setattr(st0_module, "MAX_EVALUATION_WORK", 230)
    assert f.evaluate(trace).tolist() == [True] * 10
    with pytest.raises(TraceError, match="units of work"):
        f.evaluate(trace + trace[:1])
