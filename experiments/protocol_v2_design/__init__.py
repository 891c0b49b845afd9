"""The research behind protocol v2: flyability, severe winds, faults, a privileged reference (README.md)."""
