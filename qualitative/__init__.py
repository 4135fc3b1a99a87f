"""qualgrasp.qualitative: vision, qualitative outlines, feasible regions, RCC-8, ST0, FormGrasp and
ForceGrasp. May use :mod:`qualgrasp.certify`'s grasp model; :mod:`qualgrasp.certify` never imports this package."""
