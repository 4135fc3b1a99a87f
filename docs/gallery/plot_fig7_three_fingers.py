"""
Figure 7: three fingers and the friction zone
=============================================

A three-finger ForceGrasp grasp with ``mu = 0.5`` (Ponce and Faverjon): the three friction
cones meet in a common region, the friction zone, and the three normals positively span the
plane. The grasp shown is the one with the largest certified margin.
"""

import matplotlib.pyplot as plt

from qualgrasp import synthesize
from qualgrasp.experiments.figures import fig7_three_fingers
from qualgrasp.experiments.style import RC
from qualgrasp.qualitative.objects import render

image = render("polygon")
synth = synthesize(image, fingers=3, mu=0.5, name="polygon", tolerance=False)
print(f"{len(synth.grasps)} three-finger grasps, {sum(synth.certified)} certified")

plt.rcParams.update(RC)  # the figures' own style, also when the gallery saves the picture
plt.figure(fig7_three_fingers(synth, image))  # the gallery shows the figures pyplot knows about
