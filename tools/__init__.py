"""The repository's development tools, not part of the installed package.

- :mod:`tools.architecture`: the layering contract of ``ttt_sm``, its checker and
  the ``docs/architecture.md`` page drawn from the code;
- :mod:`tools.docs`: ``python -m tools.docs export|check`` (``make docs``), every
  generated file of the repository in one command.

Run from the repository's root (``python -m tools.docs``), or from the tests,
whose ``conftest.py`` puts the root on ``sys.path``.
"""
