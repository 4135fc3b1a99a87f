"""Physical validation of certified grasps: do they hold an object in a physics engine?

The toolkit certifies closure, quality (epsilon) and tolerance (independent contact regions); this
subpackage adds an independent witness, as the field labels grasps: close the fingers on the
object, then push it, and see whether it stays.

* :mod:`~qualgrasp.experiments.physics.planar`: the planar world (pymunk, Chipmunk2D: the object
  as a rigid body of convex pieces, fingers on grooves pressed by position-controlled springs of
  bounded force, Coulomb friction, no gravity) and the trial (squeeze, then disturbance wrenches
  of growing magnitude in a set of directions; the largest resisted without slipping);
* :mod:`~qualgrasp.experiments.physics.closed_forms`: the simulator's own error on cases with
  closed-form answers;
* :mod:`~qualgrasp.experiments.physics.study`: the validation study (the qualitative, baseline and
  random grasps of the study's objects, nominal and with placement errors inside and outside
  their certified regions) and :func:`~qualgrasp.experiments.physics.study.validate`;
* :mod:`~qualgrasp.experiments.physics.plots`: its figures; :mod:`~qualgrasp.experiments.physics.cli`:
  ``qualgrasp validate``.

pymunk is an optional dependency (``pip install "qualgrasp[physics]"``), imported only where a
world is built, so the package imports without it.

A spatial backend (MuJoCo, with meshes and a gripper) goes beside :mod:`planar` as its own module
with the same three calls on its own object and finger types: ``squeeze``, ``hold`` (one wrench,
``Hold``) and ``resistance`` (the largest resisted in every direction of a 6-D direction set,
``Resistance``); the study's per-grasp trial (``_trial``) then picks the backend by the grasp's
dimension, and its rows, summary and figures stay as they are.
"""
