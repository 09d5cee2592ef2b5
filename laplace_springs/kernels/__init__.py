"""Shared numerical kernels, below every stage that computes: double-double arithmetic
(:mod:`.dd`), the first-order system with the massless reduction (:mod:`.first_order`),
and the one rule for grouping close poles (:mod:`.poles`). Each exists once; ``model``,
``exact``, ``numeric`` and ``sweeps`` import them, they import none of those.
"""
