"""Where the MP-PIC engine keeps its state on the device: rows and channels of its Taichi ndarrays.

Plain Python (no Taichi import): the kernels, the host engine (hfgpu.proppant.engine_taichi) and the host's
parcels (hfgpu.proppant.parcels: their fields and states) share these names and numbers. Every array is
allocated once per engine (the parcel arrays again when the capacity grows) and reused; the row of a field is
contiguous (structure of arrays).

Parcels (capacity ``cap``; the first ``n`` columns are in use):
    P (PARCEL_ROWS, cap) float64: X, Z [m], U, V [m/s], RADIUS [m], DENSITY [kg/m^3], PARTICLES (per parcel)
    S (STATE_ROWS, cap) int32: STATE (SUSPENDED, BRIDGED, or GONE: left through an outlet, dropped by the next
        compaction), CLASS (index of the scene's proppant class)
    W (WORK_ROWS, cap) float64, per sub-step: what the parcel sees (SEEN rows: SEEN_FIELDS, the fields of
        hfgpu.proppant.particle_ops_numpy.ParcelFluid), DRAG (D_p of its last implicit solve), LAG_X, LAG_Z
        (1 - r_p of the implicit drag, simulator module docstring)
Grid (nz, nx cells):
    C (CELL_CHANNELS, nz, nx): width, open-cell mask, dynamic pressure, the scattered moments and the fields the
        parcels read (theta_p, mean velocity, velocity variance, Sauter radius, particle stress, damping rate),
        outlet mask, the bed friction per unit mass of the overburden and the loads of the bed's slope
        (hfgpu.kernels.closures.bed)
    XF (FACE_CHANNELS, nz, nx+1) and ZF (FACE_CHANNELS, nz+1, nx): active-face mask, face width, fluid velocity,
        pressure and stress gradients, the sub-loop's mean interphase force F and implicit drag beta (Eq. 39)
    FLAGS (nz, nx) int32: stencil_flags
Deposit copies (private per parcel block on the CPU, one shared copy on a GPU):
    CD (copies, nz, nx, MOMENT_COUNT), XD (copies, nz, nx+1, 2), ZD (copies, nz+1, nx, 2): force, beta
Scalars: PR (PARAM_COUNT) float64, the run's constants (named by PARAMS); ST (STAT_COUNT) float64, what the
passes report: the sub-loop's outflow [m^3], parcels that left (ST_LEFT) and largest |u| + |v|, the first
non-finite parcel, the sort's kept and dropped counts, the solid volume in the domain.
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
# per-parcel work rows (W): the SEEN rows first, what a parcel sees: the fields of
# hfgpu.proppant.particle_ops_numpy.ParcelFluid, which builds its fields from these names
SEEN_FIELDS = ("fluid_u", "fluid_v", "dpdx", "dpdz", "dtaudx", "dtaudz", "volume_fraction", "mean_u", "mean_v",
               "damping_rate", "width")
S_UF = SEEN_FIELDS.index("fluid_u")
S_VF = SEEN_FIELDS.index("fluid_v")
S_DPDX = SEEN_FIELDS.index("dpdx")
S_DPDZ = SEEN_FIELDS.index("dpdz")
S_DTDX = SEEN_FIELDS.index("dtaudx")
S_DTDZ = SEEN_FIELDS.index("dtaudz")
S_THETA = SEEN_FIELDS.index("volume_fraction")
S_MEAN_U = SEEN_FIELDS.index("mean_u")
S_MEAN_V = SEEN_FIELDS.index("mean_v")
S_DAMPING = SEEN_FIELDS.index("damping_rate")
S_WIDTH = SEEN_FIELDS.index("width")
SEEN = len(SEEN_FIELDS)
# then the implicit drag's rows
WORK_FIELDS = SEEN_FIELDS + ("drag", "lag_x", "lag_z")
DRAG = WORK_FIELDS.index("drag")
LAG_X = WORK_FIELDS.index("lag_x")
LAG_Z = WORK_FIELDS.index("lag_z")
WORK_ROWS = len(WORK_FIELDS)

# cell channels (C); the moment sums of the scatter come first: sums over parcels of solid volume n V_p, mass,
# mass u, mass v, mass |u|^2, n r^3, n r^2 with the bilinear weights, then over the parcels a cell holds (nearest
# grid point) of n V_p and n V_p times the offset from the cell centre in cells along x and z (the averaging
# family's S, S_x, S_z, hfgpu.kernels.closures.averaging; hfgpu.proppant.particle_ops_numpy.moment_sums names its
# sums by these)
MOMENT_FIELDS = ("volume", "mass", "mass_u", "mass_v", "mass_speed2", "n_r3", "n_r2", "own_volume", "own_volume_x",
                 "own_volume_z")
M_VOLUME = MOMENT_FIELDS.index("volume")
M_MASS = MOMENT_FIELDS.index("mass")
M_MASS_U = MOMENT_FIELDS.index("mass_u")
M_MASS_V = MOMENT_FIELDS.index("mass_v")
M_MASS_SPEED2 = MOMENT_FIELDS.index("mass_speed2")
M_NR3 = MOMENT_FIELDS.index("n_r3")
M_NR2 = MOMENT_FIELDS.index("n_r2")
M_OWN = MOMENT_FIELDS.index("own_volume")
M_OWN_X = MOMENT_FIELDS.index("own_volume_x")
M_OWN_Z = MOMENT_FIELDS.index("own_volume_z")
MOMENT_COUNT = len(MOMENT_FIELDS)
(WIDTH, CELL, PRESSURE, THETA, MEAN_U, MEAN_V, VARIANCE, SAUTER, TAU, DAMPING, OUTLET,
 BED_STRENGTH, LOAD_TOP, LOAD_OWN) = range(MOMENT_COUNT, MOMENT_COUNT + 14)
CELL_CHANNELS = LOAD_OWN + 1
# face channels (XF, ZF): the same for both face sets; F_WALLS masks the nodes the fluid velocity is read on (the
# active faces and the walls, hfgpu.proppant.interpolation.velocity_nodes)
F_MASK, F_WIDTH, F_VELOCITY, F_DP, F_DTAU, F_FORCE, F_BETA, F_WALLS = range(8)
FACE_CHANNELS = 8
DEPOSIT_FORCE, DEPOSIT_BETA = range(2)

# run constants (PR), filled by name (hfgpu.proppant.engine_taichi.param_vector): a name that is an attribute of
# hfgpu.proppant.params.MppicParams takes that attribute's value; the others are the run's: the grid frame's x0,
# z0, dx, dz, the fluid's density rho_f [kg/m^3] and viscosity mu_f [Pa s], gravity [m/s^2]
PARAMS = ("x0", "z0", "dx", "dz", "theta_cp", "epsilon", "packing_restitution", "drag_law_code",
          "drag_re_coefficient", "bridging_factor", "drag_iterations", "bed_friction", "bed_stress_code",
          "bed_slope", "friction_volume_fraction",
          "shields_deposition", "wall_friction_code", "rho_f", "mu_f", "gravity", "P_s", "beta", "restitution",
          "damping", "damping_threshold", "damping_scheme_code", "averaging_code")
P_X0 = PARAMS.index("x0")
P_Z0 = PARAMS.index("z0")
P_DX = PARAMS.index("dx")
P_DZ = PARAMS.index("dz")
P_THETA_CP = PARAMS.index("theta_cp")
P_EPSILON = PARAMS.index("epsilon")
P_PACKING_RESTITUTION = PARAMS.index("packing_restitution")
P_DRAG_LAW = PARAMS.index("drag_law_code")
P_RE_COEFFICIENT = PARAMS.index("drag_re_coefficient")
P_BRIDGING = PARAMS.index("bridging_factor")
P_DRAG_ITERATIONS = PARAMS.index("drag_iterations")
P_BED_FRICTION = PARAMS.index("bed_friction")
P_BED_STRESS = PARAMS.index("bed_stress_code")
P_BED_SLOPE = PARAMS.index("bed_slope")
P_FRICTION_FRACTION = PARAMS.index("friction_volume_fraction")
P_SHIELDS = PARAMS.index("shields_deposition")
P_WALL_LAW = PARAMS.index("wall_friction_code")
P_RHO_F = PARAMS.index("rho_f")
P_MU = PARAMS.index("mu_f")
P_GRAVITY = PARAMS.index("gravity")
P_STRESS_P = PARAMS.index("P_s")
P_STRESS_BETA = PARAMS.index("beta")
P_RESTITUTION = PARAMS.index("restitution")
P_DAMPING = PARAMS.index("damping")
P_DAMPING_THRESHOLD = PARAMS.index("damping_threshold")
P_DAMPING_SCHEME = PARAMS.index("damping_scheme_code")
P_AVERAGING = PARAMS.index("averaging_code")
PARAM_COUNT = len(PARAMS)
# sub-loop reports (ST)
ST_OUTFLOW, ST_SPEED, ST_BAD_STEP, ST_BAD_PARCEL, ST_GONE, ST_LIVE, ST_VOLUME, ST_LEFT = range(8)
STAT_COUNT = 8
NO_BAD = 1e300  # ST_BAD_STEP / ST_BAD_PARCEL when every parcel state is finite
