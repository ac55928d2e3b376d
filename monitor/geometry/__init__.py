"""Frames, ellipsoid and line-of-sight geometry. Angles are radians, distances metres, unless a name says
otherwise."""
