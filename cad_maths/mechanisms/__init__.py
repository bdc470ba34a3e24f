"""Mechanism spec + scene geometry -> kinematic constants (single block, loaded wall, ...)."""
