"""The application: wires the twin, the scheduler and (later) the charts and the game."""
