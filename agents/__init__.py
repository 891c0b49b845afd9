"""Learned TVC policies (stable-baselines3): arrives with the issue "Learned TVC policies".

Nothing is importable here yet; the package exists so the project layout is fixed from the start.
"""
