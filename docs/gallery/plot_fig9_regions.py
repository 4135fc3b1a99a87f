"""
Figure 9: certified independent contact regions
===============================================

The paper's figure 4 turned into a guarantee. Left: a synthesised three-finger grasp with its
certified independent contact regions: every choice of one contact per green stretch is in force
closure, certified by :func:`~qualgrasp.certify.regions.certify_regions`; ``delta`` is how far
every finger may slide. Right: the same fingers anywhere on the whole feasible regions they lie
on is not robust, and the witness grasp (one contact per region, not in force closure) proves
it. See :ref:`concept-regions`.
"""

import matplotlib.pyplot as plt

from qualgrasp import synthesize
from qualgrasp.experiments.figures import fig9_regions
from qualgrasp.experiments.style import RC
from qualgrasp.qualitative.objects import render

image = render("polygon")
synth = synthesize(image, fingers=3, mu=0.5, name="polygon")  # with certified tolerances
print(f"median certified tolerance: {synth.summary()['median_delta_fraction']:.3f} of the object's size")

plt.rcParams.update(RC)  # the figures' own style, also when the gallery saves the picture
plt.figure(fig9_regions(synth, image))  # the gallery shows the figures pyplot knows about
