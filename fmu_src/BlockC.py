"""FMU: model C of the spring-block on a vibrating plate (corrugated plate, block confined by a force normal to the surface)."""
from pythonfmu import Fmi2Slave

from vibroblock.slave import block_slave


@block_slave("C")
class BlockC(Fmi2Slave):
    """Model C: corrugated plate, block confined by a force normal to the surface. Forces and geometry: vibroblock/models/model_c.py."""
