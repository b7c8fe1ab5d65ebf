"""One renderer per report table, each a function of the aggregated rows or of the runs."""
