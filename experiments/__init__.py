"""qualgrasp.experiments: paper-style figures, the qualitative-versus-quantitative study, the demo."""
