"""The experiments: loop functions that launch, measure and judge runs (exploration, coverage, patrol, connectivity checks)."""
