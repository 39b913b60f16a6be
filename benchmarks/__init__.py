"""Benchmarks for asymslide: run with `make bench`. Timings belong here, not in tests."""
