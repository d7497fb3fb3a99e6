"""Finite-element ingredients: constitutive laws as UFL (`laws`), the bulk forms of all
bodies (`bulk`), integration on cut cells (`cut`: moment-fitted weights, ghost penalty) and
boundary conditions and loads (`boundary`)."""
