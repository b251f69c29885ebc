"""Closure parameters of the MP-PIC particle phase (the paper, Eq. 10-16, 43)."""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import SceneError
from ..kernels.closures.averaging import AVERAGINGS
from ..kernels.closures.damping import DAMPING_SCHEMES
from ..kernels.closures.bed import BED_STRESSES
from ..kernels.closures.drag import DRAG_LAWS
from ..kernels.closures.slurry_viscosity import VISCOSITY_LAWS
from ..kernels.closures.wall_friction import WALL_FRICTION_LAWS, wall_friction_code


@dataclass(frozen=True)
class MppicParams:
    """Frozen MP-PIC closure constants; checked on construction (SceneError names ``mppic.<field>``).

    theta_cp: close-packing volume fraction (Eq. 10, 16). P_s [Pa], beta, epsilon: Harris-Crighton stress
    Eq. 16 (paper: 4 Pa, 2, 1e-7). restitution: e of the O'Rourke & Snider (2010) damping time.
    drag_law: "wen-yu" = the paper's Eq. 14 with ``drag_re_coefficient`` in front of Re^0.687 (the paper
    prints 0.5; Schiller-Naumann / Wen-Yu is 0.15, the default); "snider" = Snider (2001)
    C_d = 24/Re (theta_f^-2.65 + Re^(2/3) theta_f^-1.78 / 6) (Snider 2001).
    viscosity_law: slurry viscosity for the fluid: "power" = Eq. 10 with ``viscosity_exponent`` (-1.82),
    "krieger-dougherty" = (1 - theta/theta_cp)^(-2.5 theta_cp).
    max_relative_viscosity: cap on mu_f / mu_0 of the slurry viscosity (both laws diverge at close packing).
    A numerical regularisation, not a material constant: it only has to make the fluid of a packed bed
    effectively immobile (its wall friction 12 mu_f / (rho_f w^2), Eq. 9, then stops it within a fraction
    of a fluid step: rho_f w^2 / (12 mu_f) = 9 ms for water at 10 x 2 cP in a 1.5 mm gap) while keeping the
    pressure-correction equation well conditioned (a face coefficient d ~ 1/mu_f): a lone packed cell whose
    faces conduct cap times less than its neighbours' takes the pressure that squeezes fluid out of it, and
    that pressure kicks its parcels. On 20 ft field cells a cap of 1000 let it oscillate and grow ~3x per
    fluid step whatever the step (the step collapsed at t = 2 620 s of a 50-minute, 80 bbl/min slickwater
    stage like bench/scenes/corpus_permian_slickwater_stage.toml); 10 runs it to the end. Default 10, reached at theta_p = 0.72
    theta_cp by Eq. 10; above it the drag (Darcy flow through the pack) carries the bed's resistance.
    bridging_factor: a parcel stops where the width of its cell < bridging_factor x its diameter. Default 2:
    the lower end of the 2-3 diameters commonly quoted for bridging of a particle stream in a slot
    (van der Vlis et al. 1975; Gruesbeck & Collins 1982), lower so that parcels are not stopped early.
    drag_iterations: fixed-point iterations on D_p(u_p) in Eq. 43 (>= 1).
    packing_restitution: e of the packing limiter (Snider 2001 eqs. 39-41; MFIX MPPIC_COEFF_EN1): a parcel
    driven into a denser region faster than the mean parcel velocity is sent back at most e times its
    relative velocity. Default 0 (inelastic): a bed whose stress carries its weight is then exactly at rest.
    damping: collision damping on/off; active only where theta_p > damping_threshold x theta_cp.
    damping_scheme: how the push applies it (hfgpu.kernels.closures.damping.DAMPING_SCHEMES): "relaxation"
    (default: the old velocity relaxed towards the cell's mean, then the drag step; the cell's mean answers drag
    and gravity as without damping) or "implicit" (O'Rourke & Snider 2010, inside the drag's denominator, which
    slows the mean's answer by (1 + dt (D + h)) / (1 + dt D)).
    bed_friction: Coulomb friction coefficient mu_b of a parcel resting in or on a dense bed (push,
    hfgpu.kernels.closures.bed): its velocity along the bed (x, normal to gravity) loses at most
    dt mu_b |1 - rho_f/rho_p| g per step (the friction its own submerged weight can mobilise), so a resting grain
    stays put until the tangential drag exceeds mu_b x its submerged weight (static friction), and a sliding
    one is slowed. Default tan(28.5 deg) = 0.543, the angle of internal friction of Johnson & Jackson (1987,
    J. Fluid Mech. 176) used for sand-like beds in MFIX; 0 turns it off.
    bed_stress: the normal stress bed friction acts on (hfgpu.kernels.closures.bed): "grain" = the grain's own
    submerged weight (above); "overburden" = in a dense cell, the submerged weight of the contact network
    above down to the cell's base, sigma_v, whose shear strength mu_b sigma_v the cell's grains share (at
    least their own weight's): a bed n cells deep holds n times the drag at its base that its surface cell
    holds. Default "grain": the field-case and five-layer figures of the docs are measured with it ("overburden":
    docs/proppant-closures.md, "Bed friction").
    bed_slope: the frictional pressure of the contact network pushes the grains resting on a bed down its slope
    (hfgpu.kernels.closures.bed, slope): a_s = -(d p_f / dx) / (theta_cp rho_p), p_f the submerged weight per
    unit area of the loaded cells above, so that a bed surface steeper than atan(bed_friction) sheds its surface
    grains (the Coulomb angle of repose) and a released column slumps; the push and the bed friction are then
    taken over the drag's denominator only, and the packing cap judges a cell without the moving parcel's own
    deposit (closures.walls). false: no sideways push but Eq. 16's. Default false: with it the five-layer
    base case has 14x the grains rising in dense cells (docs/validation.md, "Angle of repose").
    averaging: the volume fraction a parcel sees in its drag and packing limiter (hfgpu.kernels.closures.averaging,
    OpenFOAM's AveragingMethods): "dual" = the bilinear deposit read back bilinearly; "basic" = its own cell's;
    "moment" = the linear function over its own cell with the first moments of the cell's parcels. Default
    "dual"; "moment" keeps the top interface of a settling suspension from piling parcels up but reads the
    sampling noise of a random packing (docs/proppant-closures.md, "Averaging", measures both).
    friction_volume_fraction: a parcel feels bed friction where theta_p of its own cell or of the cell below it
    (+z) is >= this (a contact network), and also where it lies on a floor (within one diameter of a closed
    cell or the grid edge below it); default 0.5, the onset of frictional stress of Johnson & Jackson (1987)
    (MFIX EPS_F_MIN = 0.5). Suspended parcels in a dilute suspension never feel it. The same contact network
    stops a parcel in the half cell next to a wall from moving towards that wall where its own cell has theta_p
    >= this (push, closures.walls.toward_wall_dense_numpy: a move there changes no grid field).
    wall_friction: the fluid's friction on the fracture faces: "laminar" = Eq. 9, 12 mu_f u/(rho_f w^2);
    "dean" = Eq. 9 times max(1, (0.073/12) Re^(3/4)), Re = rho_f |u| w / mu_f, Dean's (1978) turbulent skin
    friction of smooth plane-channel flow, c_f = 0.073 Re^(-1/4), past the crossing of the two laws at
    Re = 899 (identical to "laminar" below it; hfgpu.proppant.momentum).
    shields_deposition: threshold of motion on the bed surface (push, particle_ops_numpy._on_surface): a
    parcel resting on a bed surface (on a floor, or above a dense cell, its own cell loose; on_bed) stops along
    the bed (x velocity 0) while the Shields number of the bed shear stress of the fluid it sees is below the
    critical one: tau_b / ((rho_p - rho_f) g d) < theta_cr (Shields 1936; theta_cr of Soulsby & Whitehouse
    1997; tau_b = f_t sqrt(12) mu_o |u_f| / w, the surface stress of the gap-averaged flow, closures); above
    it the grain is entrained and only bed friction slows it. Default true: the threshold of motion is what
    makes a bed a bed (reasons and measurements in docs/proppant-closures.md).
    """

    theta_cp: float = 0.6
    P_s: float = 4.0
    beta: float = 2.0
    epsilon: float = 1e-7
    restitution: float = 0.9
    drag_law: str = "wen-yu"
    drag_re_coefficient: float = 0.15
    viscosity_law: str = "power"
    viscosity_exponent: float = -1.82
    max_relative_viscosity: float = 10.0
    bridging_factor: float = 2.0
    drag_iterations: int = 3
    packing_restitution: float = 0.0
    damping: bool = True
    damping_scheme: str = "relaxation"
    damping_threshold: float = 0.5
    bed_friction: float = 0.543
    bed_stress: str = "grain"
    bed_slope: bool = False
    averaging: str = "dual"
    friction_volume_fraction: float = 0.5
    wall_friction: str = "laminar"
    shields_deposition: bool = True

    def __post_init__(self) -> None:
        def bad(name: str, allowed: str) -> SceneError:
            return SceneError(f"mppic.{name}", getattr(self, name), allowed)

        if not 0.0 < self.theta_cp < 1.0:
            raise bad("theta_cp", "allowed: 0 < theta_cp < 1")
        for name in ("P_s", "epsilon"):
            if not getattr(self, name) > 0.0:
                raise bad(name, "allowed: a number > 0")
        for name in ("beta", "drag_re_coefficient", "bridging_factor", "bed_friction"):
            if not getattr(self, name) >= 0.0:
                raise bad(name, "allowed: a number >= 0")
        for name in ("restitution", "packing_restitution"):
            if not 0.0 <= getattr(self, name) <= 1.0:
                raise bad(name, f"allowed: 0 <= {name} <= 1")
        if self.drag_law not in DRAG_LAWS:
            raise bad("drag_law", f"allowed: one of {list(DRAG_LAWS)}")
        if self.viscosity_law not in VISCOSITY_LAWS:
            raise bad("viscosity_law", f"allowed: one of {list(VISCOSITY_LAWS)}")
        if self.bed_stress not in BED_STRESSES:
            raise bad("bed_stress", f"allowed: one of {list(BED_STRESSES)}")
        if self.averaging not in AVERAGINGS:
            raise bad("averaging", f"allowed: one of {list(AVERAGINGS)}")
        if self.damping_scheme not in DAMPING_SCHEMES:
            raise bad("damping_scheme", f"allowed: one of {list(DAMPING_SCHEMES)}")
        if self.wall_friction not in WALL_FRICTION_LAWS:
            raise bad("wall_friction", f"allowed: one of {list(WALL_FRICTION_LAWS)}")
        if not self.viscosity_exponent < 0.0:
            raise bad("viscosity_exponent", "allowed: a number < 0 (viscosity grows with theta_p)")
        if not self.max_relative_viscosity >= 1.0:
            raise bad("max_relative_viscosity", "allowed: a number >= 1")
        if isinstance(self.drag_iterations, bool) or not isinstance(self.drag_iterations, int) \
                or self.drag_iterations < 1:
            raise bad("drag_iterations", "allowed: an integer >= 1")
        for name in ("damping", "shields_deposition", "bed_slope"):
            if not isinstance(getattr(self, name), bool):
                raise bad(name, "allowed: true or false")
        if not 0.0 <= self.damping_threshold <= 1.0:
            raise bad("damping_threshold", "allowed: 0 <= damping_threshold <= 1")
        if not 0.0 < self.friction_volume_fraction < 1.0:
            raise bad("friction_volume_fraction", "allowed: 0 < friction_volume_fraction < 1")

    @property
    def drag_law_code(self) -> int:
        """Integer code of the drag law for kernels: 0 wen-yu (Eq. 14), 1 snider."""
        return DRAG_LAWS.index(self.drag_law)

    @property
    def bed_stress_code(self) -> int:
        """Integer code of the bed stress for kernels: 0 grain, 1 overburden (closures.bed.BED_STRESSES)."""
        return BED_STRESSES.index(self.bed_stress)

    @property
    def averaging_code(self) -> int:
        """Integer code of the averaging for kernels: 0 dual, 1 basic, 2 moment (closures.averaging.AVERAGINGS)."""
        return AVERAGINGS.index(self.averaging)

    @property
    def damping_scheme_code(self) -> int:
        """Integer code of the damping scheme for kernels: 0 implicit, 1 relaxation (closures.damping.DAMPING_SCHEMES)."""
        return DAMPING_SCHEMES.index(self.damping_scheme)

    @property
    def wall_friction_code(self) -> int:
        """Integer code of the wall-friction law for kernels (:func:`wall_friction_code`)."""
        return wall_friction_code(self.wall_friction)
