"""How ``ttt_sm`` is put together, as code: the layering contract and the page that draws it.

- :mod:`.layers`: the contract (components in tiers, who may import whom,
  no import circles) and its checker, an :mod:`ast` scan of the source;
- :mod:`.document`: ``docs/architecture.md``, generated from the code
  (``ttt-sm docs export``; a test fails when it is stale).
"""
