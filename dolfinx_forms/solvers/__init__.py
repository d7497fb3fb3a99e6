"""The contact problem and its solution: `problem` (ContactProblem), `newton` (Newton with
load steps, cut-back and the Uzawa loop), `linear` (direct, condensed and iterative linear
solves), `force_control`, `protocol` (load protocols), `checks` (self-checks of a converged
state) and `blas` (BLAS thread control)."""
