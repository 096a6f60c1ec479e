"""Multi-seed runs, sweeps and their statistics: everything that runs or summarises many runs."""
