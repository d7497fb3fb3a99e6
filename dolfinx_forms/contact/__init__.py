"""The contact set: per pair, the active set and the Coulomb friction history (trial and
committed states, eqs 26-31), the augmented Lagrangian's multipliers and their Uzawa update,
and the contact terms handed to the solver (eq 48)."""
