"""A chain of blocks on the vibrating plate (Burridge-Knopoff), built from the single
block's laws and scheme: ``kernel`` (the compiled step and the event catalogue),
``runner`` (``Chain``, what the BlockChain FMU drives), ``catalog`` (its file)."""
from .runner import CHAIN_PARAMETERS, Chain, chain_defaults  # noqa: F401
