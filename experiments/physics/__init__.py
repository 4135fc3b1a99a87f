"""Physical validation of certified grasps: do they hold an object in a physics engine?

The toolkit certifies closure, quality (epsilon) and tolerance (independent contact regions); this
subpackage adds an independent witness, as the field labels grasps: close the fingers on the
object, then push it, and see whether it stays.

* :mod:`~qualgrasp.experiments.physics.planar`: the planar world (pymunk, Chipmunk2D: the object
  as a rigid body of convex pieces, fingers on grooves pressed by position-controlled springs of
  bounded force, Coulomb friction, no gravity) and the trial (squeeze, then disturbance wrenches
  of growing magnitude in a set of directions; the largest resisted without slipping);
* :mod:`~qualgrasp.experiments.physics.closed_forms`: the simulator's own error on cases with
  closed-form answers (planar and spatial);
* :mod:`~qualgrasp.experiments.physics.study`: the validation study (the qualitative, baseline and
  random grasps of the study's objects, nominal and with placement errors inside and outside
  their certified regions) and :func:`~qualgrasp.experiments.physics.study.validate`;
* :mod:`~qualgrasp.experiments.physics.spatial`: the spatial world (MuJoCo: a mesh's convex pieces
  as a free body with the certification's mass properties, two box pads on slide joints pressed
  with a grip force) and its trial (close, release under gravity, shake; held, slip);
* :mod:`~qualgrasp.experiments.physics.spatial_study`: the spatial study (parallel-jaw poses on
  meshes, their certified least grip force against gravity, executed below and above it) and
  :func:`~qualgrasp.experiments.physics.spatial_study.validate_spatial`;
* :mod:`~qualgrasp.experiments.physics.plots`: the planar study's figures;
  :mod:`~qualgrasp.experiments.physics.cli`: ``qualgrasp validate`` (``--spatial``).

pymunk and mujoco are optional dependencies (``pip install "qualgrasp[physics]"``, with coacd for
the meshes' convex decomposition), imported only where a world is built, so the package imports
without them.
"""
