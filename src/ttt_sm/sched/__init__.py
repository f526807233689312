"""Scheduling: clocks and the control-step scheduler that wires twin and charts."""
