"""Stateflow conformance tests written from MathWorks' documented semantics examples."""
