"""ttt_sm: teach robot behaviour with statecharts on a tic-tac-toe drawing arm.

A Python reimplementation of a 2014 Brno master's thesis: the arm's charts on
python-statemachine, a digital twin of the arm with its cascade control, and
the game around them.  See README.md and docs/.
"""

__version__ = "0.1.0"
