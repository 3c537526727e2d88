//! The spacecraft for Foxglove's 3D panel: `foxglove.FrameTransforms` (N → B from σ_BN and
//! r_BN, B → each panel of the pairs and chains at its hinge angles) and a
//! `foxglove.SceneUpdate` with one box for the hub and one for each panel, sized from the
//! configuration, and a sphere for each propellant tank. Both as JSON with a JSON Schema (the
//! schema names are Foxglove's well-known ones, so the 3D panel recognises them). The chains'
//! frames and boxes are in `chains`, the tanks' spheres in `tanks`.
//!
//! # Frames (Allard & Schaub, Sec. II, Eqs. 1–7)
//! - `N` inertial; `B` hub body frame at point B: translation r_BN (N components), rotation \[NB\].
//! - `<pair>/panel1`: origin at hinge H1 (r_H1B in B), axes S1 with [S1 B] = M2(θ1) [H1 B]
//!   (ŝ11 = ĥ11 cos θ1 − ĥ13 sin θ1, `crates/dynamics/src/effectors/panel_pair/mod.rs`, `frames`).
//! - `<pair>/panel2`: origin at hinge H2 = H1 − l1 ŝ11 (S1 components (−l1, 0, 0)), axes S2 with
//!   [S2 S1] = M2(θ2 + θ_H2S1).
//!
//! A Foxglove transform from `parent` to `child` gives the child origin in the parent frame and
//! the rotation that takes child components to parent components, i.e. \[PC\] = \[CP\]ᵀ. For a
//! passive DCM \[CP\] with Euler parameters β (scalar first), that active rotation is the Hamilton
//! quaternion (w, x, y, z) = (β0, β1, β2, β3) (Schaub & Junkins, Sec. 3.5), which is what
//! [`flexdyn_kernel::attitude::dcm_to_quat`] and [`flexdyn_kernel::attitude::mrp_to_quat`] return.

use nalgebra::{Matrix3, SymmetricEigen, Vector3, Vector4};
use serde_json::{json, Value};

use flexdyn_dynamics::dynamic_effectors::magnetorquer::MagnetorquerParams;
use flexdyn_dynamics::dynamic_effectors::thruster::ThrusterParams;
use flexdyn_dynamics::effectors::panel_chain::PanelChainParams;
use flexdyn_dynamics::effectors::propellant_tank::PropellantTankParams;
use flexdyn_kernel::attitude::{dcm_to_quat, m2, mrp_to_quat};
use flexdyn_proto::{EffectorState, EnvironmentMsg, StateMsg};
use flexdyn_vehicle::config::SimConfig;

mod chains;
mod tanks;

pub use chains::{ChainGeometry, ChainLink};
pub use tanks::TankGeometry;

/// Name of the inertial frame.
pub const FRAME_N: &str = "N";
/// Name of the hub body frame.
pub const FRAME_B: &str = "B";

/// A box: centre and axes in its frame, and edge lengths.
#[derive(Clone, Debug, PartialEq)]
pub struct Cuboid {
    /// \[m\] centre, in the frame's components.
    pub center_m: Vector3<f64>,
    /// The box axes as the rotation from box to frame components, quaternion (w, x, y, z).
    pub q_frame_box: Vector4<f64>,
    /// \[m\] edge lengths along the box axes.
    pub size_m: Vector3<f64>,
}

/// One panel pair's fixed geometry.
#[derive(Clone, Debug, PartialEq)]
pub struct PairGeometry {
    /// The pair's configured name (frame ids `<name>/panel1`, `<name>/panel2`).
    pub name: String,
    /// \[m\] hinge 1 location relative to B, B components.
    pub r_h1b_b_m: Vector3<f64>,
    /// [H1 B].
    pub dcm_h1b: Matrix3<f64>,
    /// \[rad\] fixed angle of H2 about ŝ12 relative to S1.
    pub theta_h2s1_rad: f64,
    /// \[m\] panel 1 length (H1 to H2).
    pub l1_m: f64,
    /// Panel 1's box in its S1 frame.
    pub panel1: Cuboid,
    /// Panel 2's box in its S2 frame.
    pub panel2: Cuboid,
}

/// What the transforms and the scene need from a configuration.
#[derive(Clone, Debug, PartialEq)]
pub struct Geometry {
    /// The hub's box in B.
    pub hub: Cuboid,
    /// The panel pairs, in effector order (the StateMsg entries of kind `PANEL_PAIR`, in order).
    pub pairs: Vec<PairGeometry>,
    /// The panel chains (`[[panel_chains]]`), in effector order (the entries of kind
    /// `PANEL_CHAIN`).
    pub chains: Vec<ChainGeometry>,
    /// The propellant tanks (`[[propellant_tanks]]`), in effector order (the entries of kind
    /// `PROPELLANT_TANK`).
    pub tanks: Vec<TankGeometry>,
    /// The `[[environment.facets]]` plates in B (drag and solar pressure act on them): a square
    /// of the facet's area centred on its centre of pressure, normal along its box z axis.
    pub facets: Vec<Cuboid>,
    /// The thrusters (`[[thrusters]]`), in effector order: nozzle point, the direction the
    /// vehicle is pushed, and the full thrust \[N\].
    pub thrusters: Vec<ArrowMount>,
    /// The magnetorquer rods (`[[magnetorquers]]`), in effector order: centre, axis, and the
    /// largest dipole \[A·m²\].
    pub rods: Vec<ArrowMount>,
}

/// Where an actuator's arrow is drawn from, along which body axis, and the value of a full-length
/// arrow.
#[derive(Clone, Debug, PartialEq)]
pub struct ArrowMount {
    /// \[m\] the arrow's origin relative to B, B components.
    pub r_b_m: Vector3<f64>,
    /// The axis, B components (unit).
    pub axis_b: Vector3<f64>,
    /// The value drawn at [`ARROW_FULL_M`].
    pub full_scale: f64,
}

/// \[m\] length of an actuator arrow at full thrust or full dipole.
pub const ARROW_FULL_M: f64 = 0.8;

/// The plate drawn for a facet of area `area_m2` at `r_cp_b_m` with outward unit normal
/// `normal_b`: a √A × √A square, 2 % of its side thick, whose box z axis is the normal.
pub fn facet_plate(area_m2: f64, normal_b: &Vector3<f64>, r_cp_b_m: &Vector3<f64>) -> Cuboid {
    let n = normal_b.normalize();
    // The B axis least aligned with n gives an in-plane axis u = (e × n)/|e × n|; v = n × u.
    let e = (0..3)
        .map(|i| Vector3::ith(i, 1.0))
        .min_by(|a, b| n.dot(a).abs().total_cmp(&n.dot(b).abs()))
        .unwrap_or_else(Vector3::x);
    let u = e.cross(&n).normalize();
    let v = n.cross(&u);
    // Columns u, v, n map box components to B: [B P] = [P B]ᵀ (as for the hub box).
    let box_to_b = Matrix3::from_columns(&[u, v, n]);
    let side = area_m2.max(0.0).sqrt();
    Cuboid {
        center_m: *r_cp_b_m,
        q_frame_box: dcm_to_quat(&box_to_b.transpose()),
        size_m: Vector3::new(side, side, 0.02 * side),
    }
}

/// Edge lengths (a, b, c) of the homogeneous box of mass `m` with principal moments (I1, I2, I3)
/// about its centre: I1 = m(b² + c²)/12 and cyclic, so a² = 6(I2 + I3 − I1)/m and cyclic. A
/// thin plate (an edge → 0) keeps a visible thickness of 2 % of its largest edge.
pub fn equivalent_box_m(mass_kg: f64, principal_kg_m2: &Vector3<f64>) -> Vector3<f64> {
    let (i1, i2, i3) = (principal_kg_m2.x, principal_kg_m2.y, principal_kg_m2.z);
    let edge = |sq: f64| (6.0 * sq / mass_kg).max(0.0).sqrt();
    let mut e = Vector3::new(edge(i2 + i3 - i1), edge(i1 + i3 - i2), edge(i1 + i2 - i3));
    let floor = 0.02 * e.max();
    e.iter_mut().for_each(|x| *x = x.max(floor));
    e
}

/// A panel's box in its own frame S: the homogeneous box of its mass and principal inertia
/// ([`equivalent_box_m`]) with its long edge 2·d from the hinge along −ŝ1, so the box centre
/// (−d, 0, 0) is the panel's centre of mass (Eqs. 6–7), and the real `width_m` (along ŝ2) and
/// `thickness_m` (along ŝ3) where the configuration gives them. Pairs and chains alike.
pub fn panel_box(
    mass_kg: f64,
    inertia_s_kg_m2: &Vector3<f64>,
    d_m: f64,
    width_m: Option<f64>,
    thickness_m: Option<f64>,
) -> Cuboid {
    let mut size = equivalent_box_m(mass_kg, inertia_s_kg_m2);
    size.x = 2.0 * d_m;
    size.y = width_m.unwrap_or(size.y);
    size.z = thickness_m.unwrap_or(size.z);
    Cuboid {
        center_m: Vector3::new(-d_m, 0.0, 0.0),
        q_frame_box: Vector4::new(1.0, 0.0, 0.0, 0.0),
        size_m: size,
    }
}

impl Geometry {
    /// The geometry of `cfg`: the hub box from its mass and inertia about its centre of mass
    /// (along the inertia's principal axes, centred on B_c), each panel's box from its mass and
    /// principal inertia, with the panel's long edge 2·d from its hinge along −ŝ1 (so the box
    /// centre is the panel's centre of mass, Eqs. 6–7), and its `width_m` (along ŝ2) and
    /// `thickness_m` (along ŝ3) where the configuration gives them.
    pub fn from_config(cfg: &SimConfig) -> Self {
        let hub = &cfg.hub;
        let eig = SymmetricEigen::new(hub.inertia_bc_b_kg_m2);
        let mut axes = eig.eigenvectors;
        if axes.determinant() < 0.0 {
            axes.column_mut(2).neg_mut();
        }
        // Columns are the principal axes in B: that matrix maps box components to B, i.e. it is
        // [B P] = [P B]ᵀ, whose Euler parameters are those of [P B].
        let hub_box = Cuboid {
            center_m: hub.r_bcb_b_m,
            q_frame_box: dcm_to_quat(&axes.transpose()),
            size_m: equivalent_box_m(hub.mass_kg, &eig.eigenvalues),
        };
        let panel_box = |p: &flexdyn_dynamics::PanelParams| {
            panel_box(
                p.mass_kg,
                &p.inertia_s_kg_m2,
                p.d_m,
                p.width_m,
                p.thickness_m,
            )
        };
        let pairs = cfg
            .panel_pairs
            .iter()
            .map(|(p, _)| PairGeometry {
                name: p.name.clone(),
                r_h1b_b_m: p.r_h1b_b_m,
                dcm_h1b: p.dcm_h1b,
                theta_h2s1_rad: p.theta_h2s1_rad,
                l1_m: p.l1_m,
                panel1: panel_box(&p.panel1),
                panel2: panel_box(&p.panel2),
            })
            .collect();
        let facets = cfg
            .environment
            .iter()
            .flat_map(|env| &env.facets)
            .map(|f| facet_plate(f.area_m2, &f.normal_b, &f.r_cp_b_m))
            .collect();
        let thrusters = cfg
            .components
            .of::<ThrusterParams>()
            .map(|t| ArrowMount {
                r_b_m: t.r_tb_b_m,
                axis_b: t.force_axis_b.normalize(),
                full_scale: t.max_thrust_newton,
            })
            .collect();
        let rods = cfg
            .components
            .of::<MagnetorquerParams>()
            .map(|m| ArrowMount {
                r_b_m: m.r_mb_b_m,
                axis_b: m.axis_b.normalize(),
                full_scale: m.max_dipole_am2,
            })
            .collect();
        let chains = cfg
            .components
            .of::<PanelChainParams>()
            .map(ChainGeometry::new)
            .collect();
        let tanks = cfg
            .components
            .of::<PropellantTankParams>()
            .map(TankGeometry::new)
            .collect();
        Self {
            hub: hub_box,
            pairs,
            chains,
            tanks,
            facets,
            thrusters,
            rods,
        }
    }
}

fn stamp(sim_time_ns: u64) -> Value {
    json!({
        "sec": sim_time_ns / 1_000_000_000,
        "nsec": sim_time_ns % 1_000_000_000,
    })
}

fn vec3(v: &Vector3<f64>) -> Value {
    json!({"x": v.x, "y": v.y, "z": v.z})
}

/// Foxglove quaternion from Euler parameters (w, x, y, z) → {x, y, z, w}.
fn quat(q: &Vector4<f64>) -> Value {
    json!({"x": q[1], "y": q[2], "z": q[3], "w": q[0]})
}

fn transform(t_ns: u64, parent: &str, child: &str, r: &Vector3<f64>, q: &Vector4<f64>) -> Value {
    json!({
        "timestamp": stamp(t_ns),
        "parent_frame_id": parent,
        "child_frame_id": child,
        "translation": vec3(r),
        "rotation": quat(q),
    })
}

/// The StateMsg entries of wire kind `kind`, in effector order.
fn entries_of(state: &StateMsg, kind: u16) -> impl Iterator<Item = &EffectorState> {
    state.effectors.iter().filter(move |e| e.kind == kind)
}

/// The `foxglove.FrameTransforms` of one state: N → B, then B → panel 1 and panel 1 → panel 2
/// of each pair whose effector is in the message, then B → panel 1 → … → panel N of each chain
/// whose effector is (the k-th pair or chain of the geometry is the k-th entry of its kind).
/// `prefix` is prepended to every frame id
/// (e.g. `sc1/`), so several vehicles can share one scene; with a prefix, the last transform
/// is the identity from the common `N` to the vehicle's `<prefix>N` (every vehicle's inertial
/// frame is the same frame), which joins the vehicles' frame trees into one: Foxglove's 3D
/// panel draws only the frames connected to its display frame, so with `chief/B` as the display
/// frame the deputy appears at its place beside the chief.
pub fn frame_transforms(state: &StateMsg, geometry: &Geometry, prefix: &str) -> Value {
    let t = state.header.sim_time_ns;
    let sigma = Vector3::from(state.sigma_bn);
    let (n, b) = (format!("{prefix}{FRAME_N}"), format!("{prefix}{FRAME_B}"));
    let mut transforms = vec![transform(
        t,
        &n,
        &b,
        &Vector3::from(state.r_bn_n_m),
        &mrp_to_quat(&sigma),
    )];
    let pairs = entries_of(state, flexdyn_proto::effector_kind::PANEL_PAIR);
    for (pair, eff) in geometry.pairs.iter().zip(pairs) {
        let (Some(&theta1), Some(&theta2)) = (eff.states.first(), eff.states.get(2)) else {
            continue;
        };
        let dcm_s1b = m2(theta1) * pair.dcm_h1b;
        let p1 = format!("{prefix}{}/panel1", pair.name);
        let p2 = format!("{prefix}{}/panel2", pair.name);
        transforms.push(transform(
            t,
            &b,
            &p1,
            &pair.r_h1b_b_m,
            &dcm_to_quat(&dcm_s1b),
        ));
        transforms.push(transform(
            t,
            &p1,
            &p2,
            &Vector3::new(-pair.l1_m, 0.0, 0.0),
            &dcm_to_quat(&m2(theta2 + pair.theta_h2s1_rad)),
        ));
    }
    let chains = entries_of(state, flexdyn_proto::effector_kind::PANEL_CHAIN);
    for (chain, eff) in geometry.chains.iter().zip(chains) {
        transforms.extend(chain.transforms(t, prefix, eff));
    }
    if !prefix.is_empty() {
        transforms.push(transform(
            t,
            FRAME_N,
            &n,
            &Vector3::zeros(),
            &Vector4::new(1.0, 0.0, 0.0, 0.0),
        ));
    }
    json!({ "transforms": transforms })
}

/// A frame-locked, never-expiring entity (lifetime 0) of `arrows` and `cubes` in `frame`.
fn entity(t_ns: u64, frame: &str, id: &str, arrows: Value, cubes: Value) -> Value {
    json!({
        "timestamp": stamp(t_ns),
        "frame_id": frame,
        "id": id,
        "lifetime": {"sec": 0, "nsec": 0},
        "frame_locked": true,
        "metadata": [],
        "arrows": arrows,
        "cubes": cubes,
        "spheres": [],
        "cylinders": [],
        "lines": [],
        "triangles": [],
        "texts": [],
        "models": [],
    })
}

fn color(rgba: [f64; 4]) -> Value {
    json!({"r": rgba[0], "g": rgba[1], "b": rgba[2], "a": rgba[3]})
}

fn cube_entity(t_ns: u64, frame: &str, id: &str, c: &Cuboid, rgba: [f64; 4]) -> Value {
    let cubes = json!([{
        "pose": {"position": vec3(&c.center_m), "orientation": quat(&c.q_frame_box)},
        "size": vec3(&c.size_m),
        "color": color(rgba),
    }]);
    entity(t_ns, frame, id, json!([]), cubes)
}

/// A sphere entity of `diameter_m` centred at `center_m` in `frame` (none when the diameter is
/// 0: the entity then clears the last one).
fn sphere_entity(
    t_ns: u64,
    frame: &str,
    id: &str,
    center_m: &Vector3<f64>,
    diameter_m: f64,
    rgba: [f64; 4],
) -> Value {
    let mut e = entity(t_ns, frame, id, json!([]), json!([]));
    if diameter_m > 0.0 {
        let identity = Vector4::new(1.0, 0.0, 0.0, 0.0);
        e["spheres"] = json!([{
            "pose": {"position": vec3(center_m), "orientation": quat(&identity)},
            "size": vec3(&Vector3::repeat(diameter_m)),
            "color": color(rgba),
        }]);
    }
    e
}

/// The rotation (w, x, y, z) that turns x̂ onto the unit vector `d` (a Foxglove arrow points
/// along its pose's +x): about x̂ × d by the angle between them, q = (1 + x̂·d, x̂ × d)
/// normalised; about ẑ by π when d = −x̂.
fn quat_x_to(d: &Vector3<f64>) -> Vector4<f64> {
    let x = Vector3::x();
    let w = 1.0 + x.dot(d);
    if w < 1e-12 {
        return Vector4::new(0.0, 0.0, 0.0, 1.0);
    }
    let v = x.cross(d);
    Vector4::new(w, v.x, v.y, v.z).normalize()
}

/// An arrow entity in B from `from_b_m` along `dir_b` (unit) of `length_m` (no arrow when the
/// length is 0: the entity then clears the last one).
fn arrow_entity(
    t_ns: u64,
    frame: &str,
    id: &str,
    from_b_m: &Vector3<f64>,
    dir_b: &Vector3<f64>,
    length_m: f64,
    rgba: [f64; 4],
) -> Value {
    let arrows = if length_m > 0.0 {
        let head = 0.25 * length_m.max(0.2);
        json!([{
            "pose": {"position": vec3(from_b_m), "orientation": quat(&quat_x_to(dir_b))},
            "shaft_length": (length_m - head).max(0.0),
            "shaft_diameter": 0.04,
            "head_length": head,
            "head_diameter": 0.1,
            "color": color(rgba),
        }])
    } else {
        json!([])
    };
    entity(t_ns, frame, id, arrows, json!([]))
}

/// The actuators at one state, as a `foxglove.SceneUpdate` of arrows in B, or `None` for a
/// vehicle without them: each firing thruster's plume (from the nozzle, against the force,
/// [`ARROW_FULL_M`] long at full thrust, orange) and each rod's dipole (from its centre along
/// ±its axis, full length at its largest dipole, purple), and the propellant left in each
/// tank (an orange sphere inside the tank's shell, its volume the tank's fill fraction:
/// [`TankGeometry`]). A thruster that is not firing, a rod at zero or an empty tank has an
/// empty entity, which clears its arrow or sphere. Entities follow the thrusters, rods and
/// tanks of `state` in effector order.
pub fn actuator_scene(
    geometry: &Geometry,
    state: &StateMsg,
    prefix: &str,
    t_ns: u64,
) -> Option<Value> {
    if geometry.thrusters.is_empty() && geometry.rods.is_empty() && geometry.tanks.is_empty() {
        return None;
    }
    let frame = format!("{prefix}{FRAME_B}");
    let of_kind = |kind: u16| {
        state
            .effectors
            .iter()
            .filter(move |e| e.kind == kind)
            .map(|e| e.outputs.first().copied().unwrap_or(0.0))
    };
    let mut entities = Vec::new();
    for (k, (mount, thrust)) in geometry
        .thrusters
        .iter()
        .zip(of_kind(flexdyn_proto::effector_kind::THRUSTER))
        .enumerate()
    {
        let length = ARROW_FULL_M * (thrust / mount.full_scale).clamp(0.0, 1.0);
        entities.push(arrow_entity(
            t_ns,
            &frame,
            &format!("{prefix}thruster{k}"),
            &mount.r_b_m,
            &-mount.axis_b,
            length,
            [1.0, 0.45, 0.0, 0.9],
        ));
    }
    for (k, (mount, dipole)) in geometry
        .rods
        .iter()
        .zip(of_kind(flexdyn_proto::effector_kind::MAGNETORQUER))
        .enumerate()
    {
        let length = ARROW_FULL_M * (dipole.abs() / mount.full_scale).clamp(0.0, 1.0);
        entities.push(arrow_entity(
            t_ns,
            &frame,
            &format!("{prefix}rod{k}"),
            &mount.r_b_m,
            &(mount.axis_b * dipole.signum()),
            length,
            [0.55, 0.2, 0.75, 0.9],
        ));
    }
    let tanks = entries_of(state, flexdyn_proto::effector_kind::PROPELLANT_TANK);
    for (k, (tank, entry)) in geometry.tanks.iter().zip(tanks).enumerate() {
        entities.push(tank.propellant(&frame, prefix, k, entry, t_ns));
    }
    Some(json!({ "deletions": [], "entities": entities }))
}

/// \[m\] length of the Sun arrow, and of the field arrow at [`B_FULL_T`].
pub const ENV_ARROW_M: f64 = 2.0;
/// \[T\] the field drawn at [`ENV_ARROW_M`]: about the largest |B| at the surface (the IGRF
/// dipole's polar field is 2·B0 ≈ 60 µT), so every LEO field fits.
pub const B_FULL_T: f64 = 60e-6;

/// The environment at one sample, as a `foxglove.SceneUpdate` of two arrows in B from its
/// origin: the unit Sun direction `sun_b` ([`ENV_ARROW_M`] long; yellow in sunlight, its opacity
/// the shadow factor ν with a 0.2 floor, so the arrow stays visible, grey, in umbra) and the
/// field `b_b_t` (cyan, |B| / [`B_FULL_T`] of [`ENV_ARROW_M`], capped). An arrow whose model is
/// off (its [`environment_flags`] bit clear, or a zero vector) is an empty entity, which clears
/// it.
///
/// [`environment_flags`]: flexdyn_proto::environment_flags
pub fn environment_scene(env: &EnvironmentMsg, prefix: &str, t_ns: u64) -> Value {
    use flexdyn_proto::environment_flags::{MAGNETIC, SUN};
    let frame = format!("{prefix}{FRAME_B}");
    let origin = Vector3::zeros();
    let sun_b = Vector3::from(env.sun_b);
    let on = |bit: u8, v: &Vector3<f64>| env.flags & bit != 0 && v.norm() > 0.0;
    let nu = env.shadow_factor.clamp(0.0, 1.0);
    let sun_rgba = if nu > 0.0 {
        [1.0, 0.85, 0.1, nu.max(0.2)]
    } else {
        [0.5, 0.5, 0.5, 0.2]
    };
    let unit = |v: &Vector3<f64>| v.try_normalize(0.0).unwrap_or_else(Vector3::x);
    let sun = arrow_entity(
        t_ns,
        &frame,
        &format!("{prefix}sun"),
        &origin,
        &unit(&sun_b),
        if on(SUN, &sun_b) { ENV_ARROW_M } else { 0.0 },
        sun_rgba,
    );
    let b_b_t = Vector3::from(env.b_b_t);
    let field = arrow_entity(
        t_ns,
        &frame,
        &format!("{prefix}b_field"),
        &origin,
        &unit(&b_b_t),
        if on(MAGNETIC, &b_b_t) {
            ENV_ARROW_M * (b_b_t.norm() / B_FULL_T).min(1.0)
        } else {
            0.0
        },
        [0.1, 0.8, 0.9, 0.9],
    );
    json!({ "deletions": [], "entities": [sun, field] })
}

/// The colour of every panel, pairs' and chains' alike.
const PANEL_RGBA: [f64; 4] = [0.15, 0.3, 0.8, 1.0];

/// The hub's opacity when the vehicle has propellant tanks, which are usually inside it.
pub const HUB_ALPHA_WITH_TANKS: f64 = 0.35;

/// The `foxglove.SceneUpdate` that draws the spacecraft: a grey hub box in B, a blue box per
/// panel (of the pairs, then of the chains) in its own frame, a translucent gold plate per facet
/// in B, and a translucent sphere per propellant tank in B ([`TankGeometry`]; the propellant in
/// it is drawn per state, by [`actuator_scene`]; with tanks the hub is translucent,
/// [`HUB_ALPHA_WITH_TANKS`], since they are usually inside it), frame-locked and never expiring
/// (lifetime 0).
pub fn scene_update(geometry: &Geometry, prefix: &str, t_ns: u64) -> Value {
    // Tanks sit inside the bus: with any, the hub is see-through so they show.
    let hub_alpha = if geometry.tanks.is_empty() {
        1.0
    } else {
        HUB_ALPHA_WITH_TANKS
    };
    let mut entities = vec![cube_entity(
        t_ns,
        &format!("{prefix}{FRAME_B}"),
        &format!("{prefix}hub"),
        &geometry.hub,
        [0.75, 0.75, 0.78, hub_alpha],
    )];
    for pair in &geometry.pairs {
        for (which, cube) in [("panel1", &pair.panel1), ("panel2", &pair.panel2)] {
            let frame = format!("{prefix}{}/{which}", pair.name);
            entities.push(cube_entity(t_ns, &frame, &frame, cube, PANEL_RGBA));
        }
    }
    for chain in &geometry.chains {
        entities.extend(chain.entities(prefix, t_ns));
    }
    for (k, facet) in geometry.facets.iter().enumerate() {
        entities.push(cube_entity(
            t_ns,
            &format!("{prefix}{FRAME_B}"),
            &format!("{prefix}facet{k}"),
            facet,
            [0.85, 0.65, 0.13, 0.6],
        ));
    }
    let frame_b = format!("{prefix}{FRAME_B}");
    for (k, tank) in geometry.tanks.iter().enumerate() {
        entities.push(tank.shell(&frame_b, prefix, k, t_ns));
    }
    json!({ "deletions": [], "entities": entities })
}

fn obj(required: &[&str], properties: Value) -> Value {
    json!({"type": "object", "required": required, "properties": properties})
}

fn num() -> Value {
    json!({"type": "number"})
}

fn time_schema() -> Value {
    obj(
        &["sec", "nsec"],
        json!({"sec": {"type": "integer", "minimum": 0}, "nsec": {"type": "integer", "minimum": 0, "maximum": 999_999_999}}),
    )
}

fn vector3_schema() -> Value {
    obj(
        &["x", "y", "z"],
        json!({"x": num(), "y": num(), "z": num()}),
    )
}

fn quaternion_schema() -> Value {
    obj(
        &["x", "y", "z", "w"],
        json!({"x": num(), "y": num(), "z": num(), "w": num()}),
    )
}

fn frame_transform_schema() -> Value {
    let mut s = obj(
        &[
            "timestamp",
            "parent_frame_id",
            "child_frame_id",
            "translation",
            "rotation",
        ],
        json!({
            "timestamp": time_schema(),
            "parent_frame_id": {"type": "string", "description": "Name of the parent frame"},
            "child_frame_id": {"type": "string", "description": "Name of the child frame"},
            "translation": vector3_schema(),
            "rotation": quaternion_schema(),
        }),
    );
    s["title"] = json!("foxglove.FrameTransform");
    s["description"] = json!("A transform between two reference frames in 3D space");
    s
}

/// JSON Schema of `foxglove.FrameTransforms` (the fields of Foxglove's published schema that
/// this module fills).
pub fn frame_transforms_schema() -> Value {
    let mut s = obj(
        &["transforms"],
        json!({"transforms": {"type": "array", "items": frame_transform_schema()}}),
    );
    s["$schema"] = json!("https://json-schema.org/draft/2020-12/schema");
    s["title"] = json!("foxglove.FrameTransforms");
    s["description"] = json!("An array of FrameTransform messages");
    s
}

/// JSON Schema of `foxglove.SceneUpdate` (cube, sphere and arrow entities; the other primitive
/// arrays are empty).
pub fn scene_update_schema() -> Value {
    let color = obj(
        &["r", "g", "b", "a"],
        json!({"r": num(), "g": num(), "b": num(), "a": num()}),
    );
    // Foxglove's CubePrimitive and SpherePrimitive have the same fields (a sphere's size is its
    // diameters along its axes).
    let cube = obj(
        &["pose", "size", "color"],
        json!({
            "pose": obj(&["position", "orientation"], json!({"position": vector3_schema(), "orientation": quaternion_schema()})),
            "size": vector3_schema(),
            "color": color.clone(),
        }),
    );
    let sphere = cube.clone();
    let arrow = obj(
        &[
            "pose",
            "shaft_length",
            "shaft_diameter",
            "head_length",
            "head_diameter",
            "color",
        ],
        json!({
            "pose": obj(&["position", "orientation"], json!({"position": vector3_schema(), "orientation": quaternion_schema()})),
            "shaft_length": num(),
            "shaft_diameter": num(),
            "head_length": num(),
            "head_diameter": num(),
            "color": color,
        }),
    );
    let empty_array = json!({"type": "array"});
    let entity = obj(
        &[
            "timestamp",
            "frame_id",
            "id",
            "lifetime",
            "frame_locked",
            "cubes",
        ],
        json!({
            "timestamp": time_schema(),
            "frame_id": {"type": "string"},
            "id": {"type": "string"},
            "lifetime": time_schema(),
            "frame_locked": {"type": "boolean"},
            "metadata": empty_array,
            "arrows": {"type": "array", "items": arrow},
            "cubes": {"type": "array", "items": cube},
            "spheres": {"type": "array", "items": sphere},
            "cylinders": empty_array,
            "lines": empty_array,
            "triangles": empty_array,
            "texts": empty_array,
            "models": empty_array,
        }),
    );
    let mut s = obj(
        &["deletions", "entities"],
        json!({
            "deletions": {"type": "array"},
            "entities": {"type": "array", "items": entity},
        }),
    );
    s["$schema"] = json!("https://json-schema.org/draft/2020-12/schema");
    s["title"] = json!("foxglove.SceneUpdate");
    s["description"] = json!("An update to the entities displayed in a 3D scene");
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexdyn_kernel::attitude::{mrp_to_dcm, quat_to_dcm};

    fn q_of(v: &Value) -> Vector4<f64> {
        let f = |k: &str| v[k].as_f64().unwrap();
        Vector4::new(f("w"), f("x"), f("y"), f("z"))
    }

    /// Active rotation matrix of a Hamilton quaternion (w, x, y, z), written out independently
    /// of `attitude`: R = (w² − |v|²) I + 2 v vᵀ + 2 w [ṽ].
    /// The direction an arrow points (its pose's +x).
    fn direction(a: &Value) -> Vector3<f64> {
        let q = &a["pose"]["orientation"];
        let q = Vector4::new(
            q["w"].as_f64().unwrap(),
            q["x"].as_f64().unwrap(),
            q["y"].as_f64().unwrap(),
            q["z"].as_f64().unwrap(),
        );
        active(&q) * Vector3::x()
    }

    /// An arrow's whole length, shaft and head.
    fn length(a: &Value) -> f64 {
        a["shaft_length"].as_f64().unwrap() + a["head_length"].as_f64().unwrap()
    }

    fn active(q: &Vector4<f64>) -> Matrix3<f64> {
        let (w, v) = (q[0], Vector3::new(q[1], q[2], q[3]));
        let vt = Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0);
        Matrix3::identity() * (w * w - v.norm_squared()) + v * v.transpose() * 2.0 + vt * (2.0 * w)
    }

    #[test]
    fn a_prefixed_vehicle_hangs_from_the_common_inertial_frame() {
        // Two vehicles' trees join at N: chief/N and deputy/N are N itself (identity), so a
        // point fixed in deputy/B is at r_BN(deputy) − r_BN(chief) seen from chief/N.
        let geometry = Geometry::from_config(&SimConfig::reference());
        let state = StateMsg {
            r_bn_n_m: [7.0e6, -100.0, 0.0],
            ..StateMsg::default()
        };
        let plain = frame_transforms(&state, &geometry, "");
        let plain = plain["transforms"].as_array().unwrap();
        assert!(plain
            .iter()
            .all(|t| t["parent_frame_id"] != "N" || t["child_frame_id"] == "B"));
        let tf = frame_transforms(&state, &geometry, "deputy/");
        let list = tf["transforms"].as_array().unwrap();
        assert_eq!(list.len(), plain.len() + 1);
        let last = list.last().unwrap();
        assert_eq!(last["parent_frame_id"], "N");
        assert_eq!(last["child_frame_id"], "deputy/N");
        assert_eq!(q_of(&last["rotation"]), Vector4::new(1.0, 0.0, 0.0, 0.0));
        for axis in ["x", "y", "z"] {
            assert_eq!(last["translation"][axis], 0.0);
        }
        assert_eq!(list[0]["parent_frame_id"], "deputy/N");
    }

    #[test]
    fn transforms_rotate_child_components_into_the_parent_frame() {
        let cfg = SimConfig::reference();
        let geometry = Geometry::from_config(&cfg);
        assert_eq!(geometry.pairs.len(), cfg.panel_pairs.len());
        let mut state = StateMsg {
            sigma_bn: [0.1, -0.2, 0.3],
            r_bn_n_m: [7.0e6, 1.0, -2.0],
            ..StateMsg::default()
        };
        state.header.sim_time_ns = 2_500_000_001;
        state.effectors = (0..geometry.pairs.len())
            .map(|k| flexdyn_proto::EffectorState {
                kind: flexdyn_proto::effector_kind::PANEL_PAIR,
                flags: 0,
                states: vec![0.1 * (k as f64 + 1.0), 0.0, -0.05, 0.0],
                outputs: vec![],
            })
            .collect();
        let tf = frame_transforms(&state, &geometry, "");
        let list = tf["transforms"].as_array().unwrap();
        assert_eq!(list.len(), 1 + 2 * geometry.pairs.len());
        assert_eq!(list[0]["timestamp"]["sec"], 2);
        assert_eq!(list[0]["timestamp"]["nsec"], 500_000_001);
        // N → B: R maps B components to N components: R = [BN]ᵀ.
        let r_nb = active(&q_of(&list[0]["rotation"]));
        let dcm_bn = mrp_to_dcm(&Vector3::from(state.sigma_bn));
        assert!((r_nb - dcm_bn.transpose()).abs().max() < 1e-14);
        // B → panel 1: the panel's ŝ11 axis (1, 0, 0 in S1) maps to ĥ1 cos θ1 − ĥ3 sin θ1 in B.
        for (k, pair) in geometry.pairs.iter().enumerate() {
            let th1 = state.effectors[k].states[0];
            let r_b_s1 = active(&q_of(&list[1 + 2 * k]["rotation"]));
            let h = pair.dcm_h1b;
            let s11 = h.row(0).transpose() * th1.cos() - h.row(2).transpose() * th1.sin();
            assert!((r_b_s1 * Vector3::x() - s11).norm() < 1e-14);
            // Panel 1 → panel 2: rotation about ŝ12 by θ2 + θ_H2S1.
            let phi = state.effectors[k].states[2] + pair.theta_h2s1_rad;
            let r_s1_s2 = active(&q_of(&list[2 + 2 * k]["rotation"]));
            let expect = quat_to_dcm(&Vector4::new(
                (phi / 2.0).cos(),
                0.0,
                (phi / 2.0).sin(),
                0.0,
            ));
            assert!((r_s1_s2 - expect.transpose()).abs().max() < 1e-14);
            assert_eq!(list[2 + 2 * k]["translation"]["x"], -pair.l1_m);
        }
    }

    #[test]
    fn an_equivalent_box_has_the_inertia_it_came_from() {
        // A 2 × 1 × 0.5 m box of 12 kg: I = m/12 (b² + c², a² + c², a² + b²).
        let (a, b, c, m) = (2.0f64, 1.0f64, 0.5f64, 12.0);
        let i = Vector3::new(b * b + c * c, a * a + c * c, a * a + b * b) * (m / 12.0);
        let e = equivalent_box_m(m, &i);
        assert!((e - Vector3::new(a, b, c)).norm() < 1e-12, "{e}");
        // A thin plate keeps a visible thickness.
        let plate = Vector3::new(b * b, a * a, a * a + b * b) * (m / 12.0);
        let e = equivalent_box_m(m, &plate);
        assert!((e.z - 0.04).abs() < 1e-12, "{e}");
    }

    #[test]
    fn each_facet_is_a_plate_of_its_area_facing_its_normal() {
        let text = std::fs::read_to_string(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../scenarios/leo_environment.toml"),
        )
        .unwrap();
        let cfg = SimConfig::from_toml_str(&text).unwrap();
        let facets = &cfg.environment.as_ref().unwrap().facets;
        assert!(!facets.is_empty());
        let g = Geometry::from_config(&cfg);
        let scene = scene_update(&g, "sc1/", 0);
        let entities = scene["entities"].as_array().unwrap();
        assert_eq!(entities.len(), 1 + 2 * cfg.panel_pairs.len() + facets.len());
        for (k, f) in facets.iter().enumerate() {
            let e = &entities[1 + 2 * cfg.panel_pairs.len() + k];
            assert_eq!(e["frame_id"], "sc1/B");
            let cube = &e["cubes"][0];
            let at = |v: &Value, a: &str| v[a].as_f64().unwrap();
            let o = &cube["pose"]["orientation"];
            let q = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
                at(o, "w"),
                at(o, "x"),
                at(o, "y"),
                at(o, "z"),
            ));
            // The box's z axis, rotated into B, is the facet's normal; its face is A.
            assert!((q * Vector3::z() - f.normal_b).norm() < 1e-12, "facet {k}");
            let size = &cube["size"];
            assert!((at(size, "x") * at(size, "y") - f.area_m2).abs() < 1e-12);
            let p = &cube["pose"]["position"];
            assert_eq!(Vector3::new(at(p, "x"), at(p, "y"), at(p, "z")), f.r_cp_b_m);
        }
    }

    #[test]
    fn panels_with_real_dimensions_draw_as_plates_of_those_dimensions() {
        let text = flexdyn_vehicle::config::DEFAULT_CONFIG_TOML.replacen(
            "panel1 = { mass_kg = 50.0,",
            "panel1 = { width_m = 1.5, thickness_m = 0.03, mass_kg = 50.0,",
            1,
        );
        assert_ne!(text, flexdyn_vehicle::config::DEFAULT_CONFIG_TOML);
        let g = Geometry::from_config(&SimConfig::from_toml_str(&text).unwrap());
        let p = &g.pairs[0];
        // Length 2 d = 1.5 m along ŝ1, then the configured width and thickness.
        assert_eq!(p.panel1.size_m, Vector3::new(1.5, 1.5, 0.03));
        // Panel 2 has none: the box of its inertia (the reference's 2.45 m edges, 6(25+25−50)/50
        // floored at 2 % of the largest edge for the thickness).
        let edge = (6.0_f64 * 50.0 / 50.0).sqrt();
        assert!(
            (p.panel2.size_m.y - edge).abs() < 1e-12,
            "{:?}",
            p.panel2.size_m
        );
        // A bad value names the field.
        let bad = text.replacen("width_m = 1.5", "width_m = -1.0", 1);
        let e = SimConfig::from_toml_str(&bad).unwrap_err().to_string();
        assert!(e.contains("panel_pairs[0].panel1.width_m"), "{e}");
    }

    /// Thruster plumes and rod dipoles as arrows: from the nozzle against the force, from the
    /// rod along ±its axis, scaled to the full value, cleared at zero; every key the schema
    /// requires of an entity and an arrow is there.
    #[test]
    fn actuator_arrows_show_firings_and_dipoles() {
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../scenarios/acs_full.toml"
        ))
        .unwrap();
        let cfg = SimConfig::from_toml_str(&text).unwrap();
        let g = Geometry::from_config(&cfg);
        assert_eq!((g.thrusters.len(), g.rods.len()), (4, 3));
        let mut sim = flexdyn_vehicle::sim::Simulation::new(&cfg).unwrap();
        let mut state = sim.state_msg();
        // thr_pz1 at half thrust; mtq_y at −200 of 400 A·m²; everything else off.
        let kind = |k| state.effectors.iter().position(|e| e.kind == k).unwrap();
        let (t0, r0) = (
            kind(flexdyn_proto::effector_kind::THRUSTER),
            kind(flexdyn_proto::effector_kind::MAGNETORQUER),
        );
        state.effectors[t0].outputs[0] = 0.5;
        state.effectors[r0 + 1].outputs[0] = -200.0;
        let scene = actuator_scene(&g, &state, "sc1/", 7).unwrap();
        let entities = scene["entities"].as_array().unwrap();
        assert_eq!(entities.len(), 7);
        let arrow_of = |id: &str| {
            let e = entities.iter().find(|e| e["id"] == id).unwrap();
            assert_eq!(e["frame_id"], "sc1/B");
            e["arrows"].as_array().unwrap().clone()
        };
        let plume = arrow_of("sc1/thruster0");
        assert_eq!(plume.len(), 1);
        // thr_pz1 pushes +y from (1, 0, 1): the plume points −y from there, 0.4 m long.
        assert!((direction(&plume[0]) - Vector3::new(0.0, -1.0, 0.0)).norm() < 1e-12);
        assert_eq!(plume[0]["pose"]["position"]["x"], 1.0);
        assert!((length(&plume[0]) - 0.5 * ARROW_FULL_M).abs() < 1e-12);
        assert!(arrow_of("sc1/thruster1").is_empty(), "not firing: cleared");
        let rod = arrow_of("sc1/rod1");
        // mtq_y (axis +y) at −200 A·m²: along −y, half length.
        assert!((direction(&rod[0]) - Vector3::new(0.0, -1.0, 0.0)).norm() < 1e-12);
        assert!((length(&rod[0]) - 0.5 * ARROW_FULL_M).abs() < 1e-12);
        assert!(arrow_of("sc1/rod0").is_empty());
        // The schema's required keys are all there.
        let schema = scene_update_schema();
        let entity = &schema["properties"]["entities"]["items"];
        let arrow = &entity["properties"]["arrows"]["items"];
        for (e, a) in entities.iter().zip(std::iter::repeat(&plume[0])) {
            for k in entity["required"].as_array().unwrap() {
                assert!(e.get(k.as_str().unwrap()).is_some(), "entity lacks {k}");
            }
            for k in arrow["required"].as_array().unwrap() {
                assert!(a.get(k.as_str().unwrap()).is_some(), "arrow lacks {k}");
            }
        }
        // A vehicle without actuators has no actuator scene; every direction maps.
        let plain = Geometry::from_config(&SimConfig::reference());
        assert!(actuator_scene(&plain, &state, "sc1/", 0).is_none());
        for d in [Vector3::x(), -Vector3::x(), Vector3::new(0.0, 0.6, -0.8)] {
            assert!(
                (active(&quat_x_to(&d)) * Vector3::x() - d).norm() < 1e-12,
                "{d:?}"
            );
        }
    }

    /// The Sun and field arrows of the LEO scenario's first environment sample point along the
    /// message's `sun_b` and `b_b_t`, the field's length is |B| / B_FULL_T of the full arrow,
    /// the Sun arrow greys out in umbra, and a model that is off clears its arrow.
    #[test]
    fn environment_arrows_follow_the_sun_and_the_field() {
        let cfg = SimConfig::from_file(std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../scenarios/leo_environment.toml"
        )))
        .unwrap();
        let mut sim = flexdyn_vehicle::sim::Simulation::new(&cfg).unwrap();
        let mut env = EnvironmentMsg::default();
        sim.environment_into(&mut env);
        let scene = environment_scene(&env, "sc1/", 3);
        let entities = scene["entities"].as_array().unwrap();
        let arrow = |id: &str| {
            let e = entities.iter().find(|e| e["id"] == id).unwrap();
            assert_eq!(e["frame_id"], "sc1/B");
            e["arrows"].as_array().unwrap().clone()
        };
        let sun = arrow("sc1/sun");
        assert!((direction(&sun[0]) - Vector3::from(env.sun_b)).norm() < 1e-12);
        assert!((length(&sun[0]) - ENV_ARROW_M).abs() < 1e-12);
        let b = Vector3::from(env.b_b_t);
        // LEO: 20–60 µT, so the arrow is between a third of and the full length.
        assert!((20e-6..60e-6).contains(&b.norm()), "{b:?}");
        let field = arrow("sc1/b_field");
        assert!((direction(&field[0]) - b.normalize()).norm() < 1e-12);
        assert!((length(&field[0]) - ENV_ARROW_M * b.norm() / B_FULL_T).abs() < 1e-12);
        // Umbra: the Sun arrow stays, grey and faint.
        env.shadow_factor = 0.0;
        let dark = environment_scene(&env, "sc1/", 3);
        let dark_sun = &dark["entities"][0]["arrows"][0]["color"];
        assert_eq!(
            (dark_sun["r"].as_f64(), dark_sun["a"].as_f64()),
            (Some(0.5), Some(0.2))
        );
        // Models off: both entities are there, empty (they clear the arrows).
        env.flags = 0;
        let off = environment_scene(&env, "sc1/", 3);
        for e in off["entities"].as_array().unwrap() {
            assert!(e["arrows"].as_array().unwrap().is_empty(), "{e}");
        }
    }

    fn scenario(name: &str) -> SimConfig {
        SimConfig::from_file(
            &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join(format!("../../scenarios/{name}")),
        )
        .unwrap()
    }

    fn vec_of(v: &Value) -> Vector3<f64> {
        let f = |k: &str| v[k].as_f64().unwrap();
        Vector3::new(f("x"), f("y"), f("z"))
    }

    /// The pose in B (rotation R: frame → B components, origin o) of `frame`, composed from the
    /// transforms of `list` by walking parents up to `root`.
    fn pose_in(list: &[Value], root: &str, mut frame: String) -> (Matrix3<f64>, Vector3<f64>) {
        let (mut r, mut o) = (Matrix3::identity(), Vector3::zeros());
        while frame != root {
            let t = list
                .iter()
                .find(|t| t["child_frame_id"] == frame.as_str())
                .unwrap_or_else(|| panic!("no transform to {frame}"));
            let rp = active(&q_of(&t["rotation"]));
            o = rp * o + vec_of(&t["translation"]);
            r = rp * r;
            frame = t["parent_frame_id"].as_str().unwrap().to_owned();
        }
        (r, o)
    }

    /// Each chain's panels hang at their hinge angles: walking the transforms from B to panel k
    /// gives the hinge H_k and the axis ŝ_k1 of the chain's own kinematics,
    /// Φ_k = Σ_{j≤k} (θ_j + θ_Hj), ŝ_k1 = cos Φ_k ĥ11 − sin Φ_k ĥ13, H_k+1 = H_k − l_k ŝ_k1
    /// (panel_chain/mod.rs, (C1)–(C2)), written out here from the configuration; each panel has
    /// a box 2 d_k long in its frame.
    #[test]
    fn a_chain_draws_its_panels_at_their_hinge_angles() {
        let cfg = scenario("panel_chain.toml");
        let g = Geometry::from_config(&cfg);
        assert_eq!(g.chains.len(), 2);
        let mut state = flexdyn_vehicle::sim::Simulation::new(&cfg)
            .unwrap()
            .state_msg();
        let chains: Vec<usize> = (0..state.effectors.len())
            .filter(|&i| state.effectors[i].kind == flexdyn_proto::effector_kind::PANEL_CHAIN)
            .collect();
        assert_eq!(chains.len(), 2);
        // Angles far from the configuration's, distinct per panel (θ_k = 0.1 k − 0.25 c).
        for (c, &i) in chains.iter().enumerate() {
            for k in 0..state.effectors[i].states.len() / 2 {
                state.effectors[i].states[2 * k] = 0.1 * (k as f64 + 1.0) - 0.25 * c as f64;
            }
        }
        let tf = frame_transforms(&state, &g, "sc1/");
        let list = tf["transforms"].as_array().unwrap();
        // N → B, 4 + 3 panels, and the prefix's N → sc1/N.
        assert_eq!(list.len(), 1 + 4 + 3 + 1);
        for (c, params) in cfg.components.of::<PanelChainParams>().enumerate() {
            let entry = &state.effectors[chains[c]];
            let (mut phi, mut hinge) = (0.0, params.r_h1b_b_m);
            let h = params.dcm_h1b;
            for (k, p) in params.panels.iter().enumerate() {
                phi += entry.states[2 * k] + p.theta_h_rad;
                let s1 = h.row(0).transpose() * phi.cos() - h.row(2).transpose() * phi.sin();
                let frame = format!("sc1/{}/panel{}", params.name, k + 1);
                let (r, o) = pose_in(list, "sc1/B", frame);
                assert!(
                    (o - hinge).norm() < 1e-12,
                    "{} panel {k}: {o} vs {hinge}",
                    params.name
                );
                assert!(
                    (r * Vector3::x() - s1).norm() < 1e-12,
                    "{} panel {k}",
                    params.name
                );
                // Every hinge turns about ê = ĥ12.
                assert!((r * Vector3::y() - h.row(1).transpose()).norm() < 1e-12);
                hinge -= p.l_m * s1;
            }
        }
        // The scene: the hub, then one box per chain panel in its frame, 2 d_k long.
        let scene = scene_update(&g, "sc1/", 0);
        let entities = scene["entities"].as_array().unwrap();
        assert_eq!(entities.len(), 1 + 4 + 3);
        let panels = cfg
            .components
            .of::<PanelChainParams>()
            .flat_map(|c| c.panels.iter().enumerate().map(move |(k, p)| (c, k, p)));
        for (e, (c, k, p)) in entities[1..].iter().zip(panels) {
            assert_eq!(e["frame_id"], format!("sc1/{}/panel{}", c.name, k + 1));
            assert!(list.iter().any(|t| t["child_frame_id"] == e["frame_id"]));
            let cube = &e["cubes"][0];
            assert_eq!(vec_of(&cube["size"]).x, 2.0 * p.d_m);
            assert_eq!(
                vec_of(&cube["pose"]["position"]),
                Vector3::new(-p.d_m, 0.0, 0.0)
            );
        }
        // A short entry (fewer angles than panels) draws no frames rather than wrong ones.
        state.effectors[chains[0]].states.truncate(4);
        let short = frame_transforms(&state, &g, "");
        assert_eq!(short["transforms"].as_array().unwrap().len(), 1 + 3);
    }

    /// The two-panel chain of a pair (`PanelChainParams::from_pair`) is drawn exactly where the
    /// pair is: the same hinges, axes and boxes at the same angles.
    #[test]
    fn a_pair_as_a_chain_is_drawn_where_the_pair_is() {
        let cfg = SimConfig::reference();
        let (pair, initial) = &cfg.panel_pairs[0];
        let mut folded = pair.clone();
        folded.theta_h2s1_rad = 0.4; // a hinge-2 offset, so θ_H is exercised
        let chain = PanelChainParams::from_pair(&folded, initial);
        let mut g = Geometry::from_config(&cfg);
        g.pairs.truncate(1);
        g.pairs[0].theta_h2s1_rad = folded.theta_h2s1_rad;
        g.chains = vec![ChainGeometry::new(&chain)];
        g.chains[0].name = "as_chain".into();
        let (th1, th2) = (0.3, -0.7);
        let state = StateMsg {
            effectors: [
                flexdyn_proto::effector_kind::PANEL_PAIR,
                flexdyn_proto::effector_kind::PANEL_CHAIN,
            ]
            .iter()
            .map(|&kind| flexdyn_proto::EffectorState {
                kind,
                flags: 0,
                states: vec![th1, 0.0, th2, 0.0],
                outputs: vec![],
            })
            .collect(),
            ..StateMsg::default()
        };
        let tf = frame_transforms(&state, &g, "");
        let list = tf["transforms"].as_array().unwrap();
        assert_eq!(list.len(), 1 + 2 + 2);
        for k in ["panel1", "panel2"] {
            let (rp, op) = pose_in(list, "B", format!("{}/{k}", pair.name));
            let (rc, oc) = pose_in(list, "B", format!("as_chain/{k}"));
            assert!((rp - rc).abs().max() < 1e-15, "{k}");
            assert!((op - oc).norm() < 1e-15, "{k}");
        }
        assert_eq!(g.chains[0].links[0].panel, g.pairs[0].panel1);
        assert_eq!(g.chains[0].links[1].panel, g.pairs[0].panel2);
    }

    /// Each tank is a translucent sphere at its centroid, R_tank across (`radius_m`, or the
    /// sphere of the load at its density: (4/3)π R³ ρ = m_0), and the propellant a sphere inside
    /// it that holds the fill fraction of its volume: at m_0/8 its radius is R_tank/2
    /// ((1/8)^(1/3) = 1/2); an EMPTY tank clears it.
    #[test]
    fn a_tank_is_a_shell_with_its_propellant_inside() {
        let cfg = scenario("depletion.toml");
        let g = Geometry::from_config(&cfg);
        let params: Vec<&PropellantTankParams> =
            cfg.components.of::<PropellantTankParams>().collect();
        assert_eq!(g.tanks.len(), 2);
        let scene = scene_update(&g, "sc1/", 0);
        let entities = scene["entities"].as_array().unwrap();
        assert_eq!(entities.len(), 1 + 2 * cfg.panel_pairs.len() + 2);
        let shells = &entities[entities.len() - 2..];
        // The tanks are inside the hub (main at z = 0.4 m, the hub's box spans z = 1 ± 1.48 m):
        // it is see-through; without tanks it is opaque.
        let alpha = |s: &Value| s["entities"][0]["cubes"][0]["color"]["a"].as_f64().unwrap();
        assert_eq!(alpha(&scene), HUB_ALPHA_WITH_TANKS);
        assert_eq!(
            alpha(&scene_update(
                &Geometry::from_config(&SimConfig::reference()),
                "",
                0
            )),
            1.0
        );
        let diameter = |e: &Value, id: &str| {
            assert_eq!(e["id"], id);
            assert_eq!(e["frame_id"], "sc1/B");
            let spheres = e["spheres"].as_array().unwrap();
            if spheres.is_empty() {
                return 0.0;
            }
            let size = vec_of(&spheres[0]["size"]);
            assert_eq!((size.x, size.y), (size.z, size.z));
            size.x
        };
        // main: constant density, so its sphere holds the load at ρ = 1004 kg/m³.
        let r_main = diameter(&shells[0], "sc1/tank0") / 2.0;
        let rho = 1004.0;
        let mass = 4.0 / 3.0 * std::f64::consts::PI * r_main.powi(3) * rho;
        assert!((mass - 120.0).abs() < 1e-9, "{r_main} m holds {mass} kg");
        // rcs: constant volume, radius_m = 0.15.
        assert_eq!(diameter(&shells[1], "sc1/tank1"), 0.3);
        for (e, p) in shells.iter().zip(&params) {
            assert_eq!(vec_of(&e["spheres"][0]["pose"]["position"]), p.r_tcb_b_m);
        }
        // Per state, beside the 3 thrusters' plumes: full at the start.
        let mut state = flexdyn_vehicle::sim::Simulation::new(&cfg)
            .unwrap()
            .state_msg();
        let arrows = actuator_scene(&g, &state, "sc1/", 0).unwrap();
        let list = arrows["entities"].as_array().unwrap();
        assert_eq!(list.len(), 3 + 2);
        assert_eq!(diameter(&list[3], "sc1/propellant0"), 2.0 * r_main);
        assert_eq!(diameter(&list[4], "sc1/propellant1"), 0.3);
        // An eighth of main's load left: half the radius; rcs flagged empty: cleared.
        let tanks: Vec<usize> = (0..state.effectors.len())
            .filter(|&i| state.effectors[i].kind == flexdyn_proto::effector_kind::PROPELLANT_TANK)
            .collect();
        state.effectors[tanks[0]].states[0] = 120.0 / 8.0;
        state.effectors[tanks[1]].flags |= flexdyn_proto::propellant_tank_flags::EMPTY;
        let arrows = actuator_scene(&g, &state, "sc1/", 0).unwrap();
        let list = arrows["entities"].as_array().unwrap();
        assert!((diameter(&list[3], "sc1/propellant0") - r_main).abs() < 1e-12);
        assert_eq!(diameter(&list[4], "sc1/propellant1"), 0.0);
        // The schema requires of a sphere what it requires of a cube.
        let schema = scene_update_schema();
        let sphere = &schema["properties"]["entities"]["items"]["properties"]["spheres"]["items"];
        for k in sphere["required"].as_array().unwrap() {
            assert!(
                list[3]["spheres"][0].get(k.as_str().unwrap()).is_some(),
                "{k}"
            );
        }
    }

    #[test]
    fn the_scene_has_a_hub_and_two_boxes_per_pair() {
        let cfg = SimConfig::reference();
        let g = Geometry::from_config(&cfg);
        let scene = scene_update(&g, "sc1/", 0);
        let entities = scene["entities"].as_array().unwrap();
        assert_eq!(entities.len(), 1 + 2 * cfg.panel_pairs.len());
        assert_eq!(entities[0]["frame_id"], "sc1/B");
        for e in entities {
            let size = &e["cubes"][0]["size"];
            for axis in ["x", "y", "z"] {
                assert!(size[axis].as_f64().unwrap() > 0.0, "{e}");
            }
        }
    }
}
