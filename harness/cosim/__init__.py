"""FMI access and co-simulation masters: :mod:`.fmu` (extraction, instances, pools through
fmpy), :mod:`.masters` (libcosim), :mod:`.ssp` (SSP files connecting Excitation -> Block)."""
