"""Analytic references (Hertz, Cattaneo-Mindlin, the circle), comparisons of a run with them,
and sampling of the discrete solution (fields along lines, contact resultants)."""
