"""qualgrasp.certify.meshes: grasp sets on object meshes, from gripper poses to certified contacts.

* :mod:`~qualgrasp.certify.meshes.mesh`: reading meshes (trimesh), checks, mass properties;
* :mod:`~qualgrasp.certify.meshes.rays`: first hits of rays (Embree or numpy);
* :mod:`~qualgrasp.certify.meshes.gripper`: gripper descriptions and pose conventions (ACRONYM,
  GraspNet);
* :mod:`~qualgrasp.certify.meshes.contacts`: contacts from poses (approach, closing, patches);
* :mod:`~qualgrasp.certify.meshes.poses`: pose files in, certify grasp sets out;
* :mod:`~qualgrasp.certify.meshes.task`: does a grasp hold the object's weight with a grip force
  of at most ``F``? Certified both ways;
* :mod:`~qualgrasp.certify.meshes.sampling`: antipodal pose sampling.

This subpackage needs trimesh (and embreex for fast rays, h5py for ACRONYM files); the rest of
:mod:`qualgrasp.certify` does not import it.
"""

from .contacts import Outcome, Patch, fingertip_contacts, jaw_contacts
from .errors import GripperError, MeshError, PoseError, PoseFileError
from .gripper import ParallelJaw, PointHand, builtin_grippers, load_gripper, to_qualgrasp
from .mesh import MassProperties, check_mesh, load_mesh, mass_properties
from .poses import grasp_of
from .sampling import sample_poses
from .task import G, check_bound, check_every_direction, check_holds, check_slips, every_direction, least_grip

__all__ = [
    "load_mesh", "check_mesh", "mass_properties", "MassProperties",
    "load_gripper", "builtin_grippers", "ParallelJaw", "PointHand", "to_qualgrasp",
    "jaw_contacts", "fingertip_contacts", "Patch", "Outcome", "grasp_of", "sample_poses",
    "G", "least_grip", "check_holds", "check_slips", "check_bound", "every_direction",
    "check_every_direction",
    "MeshError", "GripperError", "PoseError", "PoseFileError",
]
