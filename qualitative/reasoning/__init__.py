"""Qualitative spatial and temporal reasoning: RCC-8, grasp scenes, ST0 and the grasp phases.

* :mod:`.rcc8`: the eight base relations between regions, composition, path consistency;
* :mod:`.st0`: ST0 formulas (temporal operators over RCC-8 atoms), their parser, traces and
  evaluation;
* :mod:`.scene`: a grasp scene's regions (object, fingers, approach zones, grasp regions) and
  their relations;
* :mod:`.phases`: the grasp phases as ST0 formulas.

Reasoning works on regions (shapely geometry) and relation names only: it imports nothing of
:mod:`qualgrasp.qualitative.vision`, :mod:`~qualgrasp.qualitative.synthesis` or
:mod:`~qualgrasp.qualitative.plots` (a structure test checks it).

Examples
--------
>>> from qualgrasp.qualitative.reasoning import compose
>>> sorted(compose("TPP", "NTPP"))
['NTPP']
"""

from .rcc8 import (RELATIONS, compose, consistent, consistent_scenario, converse, path_consistency, relation,
                   relations_among)
from .st0 import (MAX_ARRANGEMENT_WORK, MAX_DEPTH, MAX_EVALUATION_WORK, MAX_FORMULA, MAX_TRACE_BYTES, Always, And,
                  Atom, Const, Formula, Historically, Implies, Next, Not, Once, Or, Previous, Since, Sometime, Until,
                  evaluate_file, parse, read_trace, write_trace)
from .scene import approach_zone, finger_disc, grasp_region, grasp_scene, scene_regions
from .phases import PHASES, grasp_trace, no_penetration, phase_formulas, phase_sequence, phases_of, placement_order

__all__ = [
    "RELATIONS", "relation", "converse", "compose", "relations_among", "path_consistency", "consistent_scenario",
    "consistent",
    "Formula", "Const", "Atom", "Not", "And", "Or", "Implies", "Next", "Sometime", "Always", "Until", "Previous",
    "Once", "Historically", "Since", "parse", "read_trace", "write_trace", "evaluate_file",
    "MAX_FORMULA", "MAX_DEPTH", "MAX_TRACE_BYTES", "MAX_ARRANGEMENT_WORK", "MAX_EVALUATION_WORK",
    "finger_disc", "approach_zone", "grasp_region", "scene_regions", "grasp_scene",
    "PHASES", "phase_formulas", "phase_sequence", "placement_order", "no_penetration", "phases_of", "grasp_trace",
]
