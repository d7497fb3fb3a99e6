"""Results: atomic output folders (`folders`), metrics.json (`results`), tables, fields and
plots (`output`, `plot_worker`)."""
