"""The lab: exercises in which a student writes one of the thesis' charts, and checks of what it does.

:mod:`.exercise` lists the packaged exercises and copies one into a student's
folder; :mod:`.checks` runs a folder's chart in its slot of the robot
(:mod:`ttt_sm.app.slots`) and judges its behaviour (docs/lab.md).
"""
