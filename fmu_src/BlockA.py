"""FMU: model A of the spring-block on a vibrating plate (flat plate, block confined by gravity)."""
from pythonfmu import Fmi2Slave

from vibroblock.slave import block_slave


@block_slave("A")
class BlockA(Fmi2Slave):
    """Model A: flat plate, block confined by gravity. Forces and geometry: vibroblock/models/model_a.py."""
