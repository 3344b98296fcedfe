"""FMU (FMI 3.0): BlockChain.fmu's chain with N a structural parameter and the blocks'
outputs as the arrays x[N] and vx[N]; the same core and facade (vibroblock/chain/),
presented through pythonfmu3 (vibroblock/fmi3.py).
"""
from pythonfmu3 import Fmi3Slave

from vibroblock.chain.slave3 import chain_fmu3

# The number of blocks a master gets unless it sets the structural parameter N.
N_BLOCKS = 16


@chain_fmu3(N_BLOCKS)
class BlockChain3(Fmi3Slave):
    """A chain of blocks on a vibrating plate (Burridge-Knopoff), FMI 3.0 arrays."""
