"""FMU: a chain of blocks on a vibrating plate (Burridge-Knopoff), each block model A's
contact and friction, neighbours coupled by springs; event catalogue and its counts.
The chain: vibroblock/chain/; the FMI machinery (errors, time, FMU state) is shared
with the other FMUs: vibroblock/fmi.py.
"""
from pythonfmu import Fmi2Slave

from vibroblock.chain.slave import chain_fmu

# The number of blocks, fixed when the FMU is built (its outputs x[1] ... x[N]):
# ``python build/build_fmus.py BlockChain --chain-blocks N`` builds another N.
N_BLOCKS = 16


@chain_fmu(N_BLOCKS)
class BlockChain(Fmi2Slave):
    """A chain of blocks on a vibrating plate (Burridge-Knopoff)."""
