"""PID and gain-scheduled PID TVC baselines: arrive with the issue "PID and gain-scheduled PID".

Nothing is importable here yet; the package exists so the project layout is fixed from the start.
"""
