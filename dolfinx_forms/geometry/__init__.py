"""Contact geometry on the DOLFINx mesh: contact pairs (the intermediate contact surface,
eq 21, its quadrature and closest-point projections, eq 25), location of points in cells
(body-fitted and cut grids), and rigid level-set obstacles."""
