"""What runs produce: rerun recordings, parameter sweeps, the benchmark."""
