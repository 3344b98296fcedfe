"""FMU: model B of the spring-block on a vibrating plate (corrugated plate, block confined by gravity)."""
from pythonfmu import Fmi2Slave

from vibroblock.slave import block_slave


@block_slave("B")
class BlockB(Fmi2Slave):
    """Model B: corrugated plate, block confined by gravity. Forces and geometry: vibroblock/models/model_b.py."""
