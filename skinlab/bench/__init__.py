"""Benchmarks (not tests): timings are measured and printed, never asserted."""
