"""Test helpers for the block chain beside the single block."""
from __future__ import annotations

import numpy as np

from vibroblock.chain import Chain


def chain_of(n, **parameters):
    """A chain of n blocks with the single block's parameter names (its drive spring k_d is
    the chain's leaf spring k_p)."""
    return Chain(n, **{("k_p" if k == "k_d" else k): v for k, v in parameters.items()})


def run_side_by_side(block, chain, times=np.arange(1, 61) * 50.0):
    """Start a single block and a chain and advance both through ``times``."""
    block.start()
    chain.start()
    for t in times:
        block.advance_to(t)
        chain.advance_to(t)
