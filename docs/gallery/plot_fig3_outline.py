"""
Figure 3: the qualitative outline
=================================

The figure-3 object seen by a camera (a synthetic 512 x 512 image), its contour cut into
segments of Galton and Meathrel's seven curvature types, and the canonical string read clockwise
from the arrow. The string in the title is the one :func:`~qualgrasp.qualitative.vision.outline.outline_image`
computes, not a caption typed in.
"""

import matplotlib.pyplot as plt

from qualgrasp.experiments.figures import fig3_outline
from qualgrasp.experiments.style import RC
from qualgrasp.qualitative.objects import render
from qualgrasp.qualitative.vision.outline import outline_image

image = render("figure3")
outline = outline_image(image)
print("canonical string:", outline.string)

plt.rcParams.update(RC)  # the figures' own style, also when the gallery saves the picture
fig = fig3_outline(image)
plt.figure(fig)  # the gallery shows the figures pyplot knows about
