"""qualgrasp.qualitative: vision, qualitative outlines, feasible regions, RCC-8, ST0, FormGrasp and
ForceGrasp. May use :mod:`qualgrasp.certify`'s grasp model; :mod:`qualgrasp.certify` never imports this package.

The subpackages, one concept each (each ``__init__`` lists its public names):

* :mod:`~qualgrasp.qualitative.vision`: from an image to the object's contour and its qualitative
  outline (image headers, segmentation, contour, edge evidence, outline and scales);
* :mod:`~qualgrasp.qualitative.reasoning`: RCC-8, grasp scenes, ST0 and the grasp phases
  (imports nothing of vision or synthesis);
* :mod:`~qualgrasp.qualitative.synthesis`: feasible regions, candidates, zones, FormGrasp and
  ForceGrasp, the registered procedures, independent regions and :func:`synthesize
  <qualgrasp.qualitative.synthesis.pipeline.synthesize>`;
* :mod:`~qualgrasp.qualitative.plots`: the figures, above the domain code (no domain module
  imports them).

At the top: :mod:`~qualgrasp.qualitative.objects` (the built-in objects and their synthetic
images), :mod:`~qualgrasp.qualitative.errors` (the exceptions) and
:mod:`~qualgrasp.qualitative.cli` (the commands).
"""
