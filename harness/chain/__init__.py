"""The chain of blocks (BlockChain FMU): its event catalogues read into pandas or obspy
(``catalog``), the statistics seismologists read from them (``statistics``), and runs
of the FMU through fmpy (``run``)."""
