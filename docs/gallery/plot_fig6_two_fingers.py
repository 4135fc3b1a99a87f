"""
Figure 6: two fingers with friction
===================================

A two-finger ForceGrasp grasp with ``mu = 0.5``: each finger's friction cone (half-angle
``theta_min = atan(mu)``) and the grasp line between the fingers. Nguyen's condition: the grasp is
in force closure when the grasp line lies strictly inside both cones. The figure shows the
certified pair whose angles to the grasp line are largest, with those angles.
"""

import matplotlib.pyplot as plt

from qualgrasp import synthesize
from qualgrasp.experiments.figures import fig6_two_fingers
from qualgrasp.experiments.style import RC
from qualgrasp.qualitative.objects import render

image = render("polygon")
synth = synthesize(image, fingers=2, mu=0.5, name="polygon", tolerance=False)
print(f"{len(synth.grasps)} two-finger grasps, {sum(synth.certified)} certified")

plt.rcParams.update(RC)  # the figures' own style, also when the gallery saves the picture
plt.figure(fig6_two_fingers(synth, image))  # the gallery shows the figures pyplot knows about
