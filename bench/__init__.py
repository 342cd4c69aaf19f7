"""Benchmarks of the service (issue 16): `python -m bench.serve`; not part of the test suite."""
