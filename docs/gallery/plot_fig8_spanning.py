"""
Figure 8: normals that positively span the plane
================================================

Left: the normals of a three-finger grasp in force closure positively span the plane (every
gap between consecutive normals is below 180 degrees). Right: the third contact replaced by a
point of a feasible region whose normal leaves all three in a half-plane, which
:func:`qualgrasp.certify_grasp` finds not in force closure. The same test, on the normals as rays,
is :func:`qualgrasp.positive_span`.
"""

import matplotlib.pyplot as plt

from qualgrasp import synthesize
from qualgrasp.experiments.figures import fig8_spanning
from qualgrasp.experiments.style import RC
from qualgrasp.qualitative.objects import render

image = render("polygon")
synth = synthesize(image, fingers=3, mu=0.5, name="polygon", tolerance=False)

plt.rcParams.update(RC)  # the figures' own style, also when the gallery saves the picture
plt.figure(fig8_spanning(synth, image))  # the gallery shows the figures pyplot knows about
