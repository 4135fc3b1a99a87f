"""qualgrasp.qualitative: vision, qualitative outlines, feasible regions, RCC-8, ST0, FormGrasp and
ForceGrasp. May use :mod:`certify`'s grasp model; :mod:`certify` never imports this package."""
