"""
The comparison study, quick setting
===================================

Qualitative grasps (FormGrasp with four frictionless fingers, ForceGrasp with two and three
fingers at ``mu = 0.5``) against the quantitative baseline (the grasps of largest certified L1
epsilon over densely sampled boundary contacts) on the four built-in objects, in the study's
quick setting: about a minute on two cores. :func:`~qualgrasp.experiments.study.compare` writes
tables (CSV and Markdown) and the four plots shown below; ``qualgrasp compare --builtins`` runs the
same study from the command line, and ``qualgrasp compare --builtins --silhouettes 24 --wings 36``
the 65-object study of the README. See :ref:`concept-study` for what is measured.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt

from qualgrasp.experiments.design import BUILTINS
from qualgrasp.experiments.study import compare

out = Path(tempfile.mkdtemp(prefix="qualgrasp-study-"))
result = compare(BUILTINS, out, settings="quick")


def cell(value, spec=".3f"):
    return "-" if value is None else format(value, spec)


print(f"{len(result.objects)} objects in {result.seconds:.0f} s")
print("route           grasps  eps best  best/baseline  robustness  tolerance")
for r in result.routes:
    print(f"{r.route:<14} {r.grasps:>7} {cell(r.eps_best):>9} {cell(r.ratio_best, '.2f'):>14} "
          f"{cell(r.robustness):>11} {cell(r.delta_median):>10}")


def show(name: str, dpi: float = 200) -> None:
    """The PNG the study wrote, pixel for pixel, as a pyplot figure (which the gallery shows)."""
    picture = plt.imread(out / f"{name}.png")
    fig = plt.figure(figsize=(picture.shape[1] / dpi, picture.shape[0] / dpi), dpi=dpi)
    fig.figimage(picture)


# %%
# Epsilon
# -------
# Certified L1 epsilon of every certified grasp each route returned (boxes) and each object's
# best (dots), one panel per finger count.
show("study-epsilon")

# %%
# Quality against time
# --------------------
# Each object's best certified epsilon against the time from image to certified grasps.
show("study-quality-time")

# %%
# Robustness to vision errors
# ---------------------------
# The fraction of planned grasps that still certify when executed on the true object after a
# pose error (rotation, translation) or a shape error (noise, blur, segmentation threshold) of
# the image they were planned on.
show("study-robustness")
# sphinx_gallery_thumbnail_number = 3

# %%
# Certified tolerance
# -------------------
# How far every finger of each object's best grasp may slide along the outline with force
# closure still certified (independent contact regions, fraction of the object's size), beside
# the route's sampled robustness.
show("study-tolerance")
