"""Where the MP-PIC engine keeps its state on the device: rows and channels of its Taichi ndarrays.

Plain Python (no Taichi import): the kernels, the host engine (hfgpu.proppant.engine_taichi) and the host's
parcels (hfgpu.proppant.parcels: their fields and states) share these names and numbers. Every array is
allocated once per engine (the parcel arrays again when the capacity grows) and reused; the row of a field is
contiguous (structure of arrays).

Parcels (capacity ``cap``; the first ``n`` columns are in use):
    P (PARCEL_ROWS, cap) float64: X, Z [m], U, V [m/s], RADIUS [m], DENSITY [kg/m^3], PARTICLES (per parcel)
    S (STATE_ROWS, cap) int32: STATE (SUSPENDED, BRIDGED, or GONE: left through an outlet, dropped by the next
        compaction), CLASS (index of the scene's proppant class)
    W (WORK_ROWS, cap) float64, per sub-step: what the parcel sees (SEEN rows in the order of
        hfgpu.proppant.particle_ops_numpy.ParcelFluid), DRAG (D_p of its last implicit solve), LAG_X, LAG_Z
        (1 - r_p of the implicit drag, simulator module docstring)
Grid (nz, nx cells):
    C (CELL_CHANNELS, nz, nx): width, open-cell mask, dynamic pressure, the scattered moments and the fields the
        parcels read (theta_p, mean velocity, velocity variance, Sauter radius, particle stress, damping rate),
        outlet mask
    XF (FACE_CHANNELS, nz, nx+1) and ZF (FACE_CHANNELS, nz+1, nx): active-face mask, face width, fluid velocity,
        pressure and stress gradients, the sub-loop's mean interphase force F and implicit drag beta (Eq. 39)
    FLAGS (nz, nx) int32: stencil_flags
Deposit copies (private per parcel block on the CPU, one shared copy on a GPU):
    CD (copies, nz, nx, MOMENT_COUNT), XD (copies, nz, nx+1, 2), ZD (copies, nz+1, nx, 2): force, beta
Scalars: PR (PARAM_COUNT) float64, the run's constants; ST (STAT_COUNT) float64, what the passes report: the
sub-loop's outflow [m^3], parcels that left (ST_LEFT) and largest |u| + |v|, the first non-finite parcel, the
sort's kept and dropped counts, the solid volume in the domain.
"""

# parcel rows (P): the float fields of hfgpu.proppant.parcels.Parcels, which builds its fields from these names
FLOAT_FIELDS = ("x", "z", "u", "v", "radius", "density", "particles")
X, Z, U, V, RADIUS, DENSITY, PARTICLES = range(len(FLOAT_FIELDS))
PARCEL_ROWS = len(FLOAT_FIELDS)
# parcel integer rows (S): the integer fields of Parcels
INT_FIELDS = ("state", "class_id")
STATE, CLASS = range(len(INT_FIELDS))
STATE_ROWS = len(INT_FIELDS)
# parcel states (the STATE row, Parcels.state)
SUSPENDED, BRIDGED, GONE = 0, 1, 2
# per-parcel work rows (W): the SEEN rows first
S_UF, S_VF, S_DPDX, S_DPDZ, S_DTDX, S_DTDZ, S_THETA, S_MEAN_U, S_MEAN_V, S_DAMPING, S_WIDTH = range(11)
SEEN = 11
DRAG, LAG_X, LAG_Z = 11, 12, 13
WORK_ROWS = 14

# cell channels (C); the moment sums of the scatter come first, in hfgpu.proppant.particle_ops_numpy order
M_VOLUME, M_MASS, M_MASS_U, M_MASS_V, M_MASS_SPEED2, M_NR3, M_NR2 = range(7)
MOMENT_COUNT = 7
WIDTH, CELL, PRESSURE, THETA, MEAN_U, MEAN_V, VARIANCE, SAUTER, TAU, DAMPING, OUTLET = range(7, 18)
CELL_CHANNELS = 18
# face channels (XF, ZF): the same for both face sets
F_MASK, F_WIDTH, F_VELOCITY, F_DP, F_DTAU, F_FORCE, F_BETA = range(7)
FACE_CHANNELS = 7
DEPOSIT_FORCE, DEPOSIT_BETA = range(2)

# run constants (PR)
(P_X0, P_Z0, P_DX, P_DZ, P_THETA_CP, P_EPSILON, P_PACKING_RESTITUTION, P_DRAG_LAW, P_RE_COEFFICIENT,
 P_BRIDGING, P_DRAG_ITERATIONS, P_BED_FRICTION, P_FRICTION_FRACTION, P_SHIELDS, P_WALL_LAW, P_RHO_F, P_MU,
 P_GRAVITY, P_STRESS_P, P_STRESS_BETA, P_RESTITUTION, P_DAMPING, P_DAMPING_THRESHOLD) = range(23)
PARAM_COUNT = 23
# sub-loop reports (ST)
ST_OUTFLOW, ST_SPEED, ST_BAD_STEP, ST_BAD_PARCEL, ST_GONE, ST_LIVE, ST_VOLUME, ST_LEFT = range(8)
STAT_COUNT = 8
NO_BAD = 1e300  # ST_BAD_STEP / ST_BAD_PARCEL when every parcel state is finite
