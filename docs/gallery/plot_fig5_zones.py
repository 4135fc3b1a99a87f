"""
Figure 5: zones of freedom of a FormGrasp grasp
===============================================

FormGrasp places four frictionless fingers one after the other. After each contact the zone of
freedom shrinks: the centres of rotation still allowed clockwise on screen (``Z+``, turning +x
towards +y with y pointing down) and counter-clockwise (``Z-``), and the translations still
allowed. The grasp is in form closure when nothing is left
(Reuleaux's method, see :ref:`concept-synthesis`). The grasp shown is a synthesised one, and its
certified margin comes from :func:`qualgrasp.certify_grasp`.
"""

import matplotlib.pyplot as plt

from qualgrasp import synthesize
from qualgrasp.experiments.figures import fig5_zones
from qualgrasp.experiments.style import RC
from qualgrasp.qualitative.objects import render

image = render("polygon")
synth = synthesize(image, fingers=4, name="polygon", tolerance=False)
summary = synth.summary()
print(f"{summary['procedure']}: {summary['certified']} of {summary['grasps']} grasps certified")

plt.rcParams.update(RC)  # the figures' own style, also when the gallery saves the picture
plt.figure(fig5_zones(synth, image))  # the gallery shows the figures pyplot knows about
