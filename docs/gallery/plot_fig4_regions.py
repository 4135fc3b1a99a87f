"""
Figure 4: feasible grasp regions
================================

Feasible grasp regions (the paper's definitions 1 and 2) on the irregular polygon, the
hexagonal nut and the circular contour. Straight segments are feasible; a curve is feasible
where its bounding circle under a finger pad is wider than ``alpha`` times the object's size (the
dashed circle), so only part of the disc qualifies. See :ref:`concept-outline`.
"""

import matplotlib.pyplot as plt

from qualgrasp.experiments.figures import fig4_regions
from qualgrasp.experiments.style import RC
from qualgrasp.qualitative.objects import render
from qualgrasp.qualitative.vision.outline import outline_image
from qualgrasp.qualitative.synthesis.regions import feasible_regions

for name in ("polygon", "nut", "disc"):
    regions = feasible_regions(outline_image(render(name)))
    print(f"{name}: {len(regions)} feasible regions")

plt.rcParams.update(RC)  # the figures' own style, also when the gallery saves the picture
plt.figure(fig4_regions())  # the gallery shows the figures pyplot knows about
