"""What the kit's tests and its fuzzing and benchmark tools share, as
numpy.testing is numpy's: an in-process runner for `fsw` (runner), the
Hypothesis strategies that draw valid projects (strategies) and the
settings of the property tests (properties), and the front end's mutation
fuzzer (fuzz).

Importing this package imports nothing; strategies and properties need
Hypothesis (the `test` extra: pip install fswkit[test])."""
