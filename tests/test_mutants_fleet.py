"""Tests written to kill mutants of benchmarks/mutation_check.py (issue 27 item 6)."""
