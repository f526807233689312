"""How ``ttt_sm`` is put together, as code: the layering contract and the page that draws it.

- :mod:`.layers`: the contract (components in tiers, who may import whom,
  no import circles) and its checker, an :mod:`ast` scan of the source;
- :mod:`.document`: ``docs/architecture.md``, generated from the code
  (``make docs``; a test fails when it is stale).

A development tool of the repository: not in the installed package.
"""
