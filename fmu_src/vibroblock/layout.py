"""Index layout of the arrays the numba kernels share.

The dynamic state lives in a few flat arrays so that it can be saved, restored and
serialised whole (FMU state) and handed to compiled kernels without conversion.
"""

# Physical parameters, float64 array ``prm``.
P_M, P_G, P_KN, P_KT, P_GN, P_GT, P_MUS, P_KD, P_VD, P_AX, P_WX, P_PL = range(12)
N_PRM = 12
PRM_NAMES = ("m", "g", "k_n", "k_t", "gamma_n", "gamma_t", "mu_s", "k_d", "V_d", "A_x", "omega_x", "P_l")

# Continuous state, float64 array ``y``: block position and velocity, the tangential
# spring's displacement F (Cundall-Strack), the integral of (vx - V_d)^2 and the
# compensation term of its Kahan sum (the integral runs over up to 1e12 steps), and the
# energy balance: work done on the block, energy dissipated (dashpots and resets), energy
# stored in the normal spring, and the stored energy at the start.
Y_X, Y_Z, Y_VX, Y_VZ, Y_F, Y_PHI, Y_PHI_C, Y_WORK, Y_DISSIPATED, Y_E_NORMAL, Y_E_START = range(11)
N_Y = 11

# Integer counters, int64 array ``cnt``: internal steps taken since the start (time is
# t0 + n dt, never accumulated), Coulomb resets, and the step at which the drive phase
# was last re-anchored (omega is tunable; the phase stays continuous when it changes).
C_STEP, C_SLIPS, C_PHASE_STEP = range(3)
N_CNT = 3

# Clock and plate drive, float64 array ``drv``: start time, step, harmonic amplitude,
# angular frequency, drive phase at C_PHASE_STEP, and the external plate input
# (height, velocity, acceleration) with the communication time at which it was set.
D_T0, D_DT, D_AMP, D_OMEGA, D_PHASE, D_EXT_Z, D_EXT_V, D_EXT_A, D_EXT_T = range(9)
N_DRV = 9
