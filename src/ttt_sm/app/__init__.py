"""The application: the robot (the twin or the arm, the scheduler, the thesis' charts wired to them),
the game around it, drawing and its precision, the Safety chart's monitor; docs/architecture.md maps
each module to the thesis."""
