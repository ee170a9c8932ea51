//! The element blocks of the matrices the analyses factor: the tangent stiffness `K_T(q)`
//! (the elastic tangent `K_t + EA ε̄ S_l + (EA/l)(S_l e)(S_l e)ᵀ`, whose middle term is the
//! geometric stiffness of the axial force, plus the Jacobian of the follower moments
//! `−∂Q_M/∂q`) and the mass `M`, at the parameters `μ`, each as one 8×8 block per element
//! for [`crate::linalg::kkt::KktSolver`]; and the KKT pattern of a system.

use crate::linalg::kkt::{make_solver, Block, KktPattern, KktSolver, LinearSolverKind};
use crate::physics::system::FlexibleSystem;
use crate::solver::model::{ElementModel, IterationCoefficients, Parameters, ParametricModel};

/// The KKT pattern of `sys`: its blocks' dof maps (the elements', then the coupling blocks
/// of springs between nodes no element holds together) and its constraint rows `B`.
pub fn pattern(sys: &FlexibleSystem) -> KktPattern {
    KktPattern {
        n_dof: ParametricModel::n_dof(sys),
        element_dofs: (0..sys.n_blocks()).map(|k| *sys.block_dofs(k)).collect(),
        constraint_rows: sys.constraints.iter().map(|c| c.terms.clone()).collect(),
    }
}

/// A KKT solver of `kind` over `sys`'s pattern.
pub fn solver(sys: &FlexibleSystem, kind: LinearSolverKind) -> Box<dyn KktSolver> {
    make_solver(kind, pattern(sys))
}

/// `K_T(q)` at `μ` as element blocks (then zero coupling blocks), the loads' Jacobian
/// times `load_factor` (the loads are linear in their magnitude, so a ramped load has the
/// ramped Jacobian; a spring is ramped with them). Each element's elastic tangent is the
/// file's times `E(μ)/E_file` (force and tangent are linear in E). At rest (`q̇ = 0`).
pub fn tangent_blocks(sys: &FlexibleSystem, mu: &Parameters, q: &[f64], t: f64, load_factor: f64) -> Vec<Block> {
    let coef = IterationCoefficients { mass: 0.0, damping: 0.0, stiffness: 1.0 };
    let mut blocks: Vec<Block> = (0..sys.n_elements())
        .map(|e| {
            let d = sys.element_dofs(e);
            let qe: Vec<f64> = d.iter().map(|&i| q[i]).collect();
            let mut out = [0.0; 64];
            sys.element_matrix(e, &qe, coef, &mut out);
            Block::from_column_slice(&out) * sys.stiffness_factor(e, mu)
        })
        .collect();
    blocks.resize(sys.n_blocks(), Block::zeros());
    add_load_jacobian(sys, mu, q, t, load_factor, &mut blocks);
    blocks
}

/// Adds `load_factor · (−∂Q_ext/∂q)` into the blocks: an entry that couples two coordinates
/// of one element (a moment acts on its node's slope) goes to the first element holding
/// its row's coordinate, one between nodes no element holds together (a spring's) to the
/// coupling block of the two nodes.
fn add_load_jacobian(sys: &FlexibleSystem, mu: &Parameters, q: &[f64], t: f64, factor: f64, blocks: &mut [Block]) {
    let dofs = sys.load_dofs();
    let nl = dofs.len();
    if nl == 0 || factor == 0.0 {
        return;
    }
    let ql: Vec<f64> = dofs.iter().map(|&d| q[d]).collect();
    let mut j = vec![0.0; nl * nl];
    sys.load_jacobian(mu, &ql, &vec![0.0; nl], t, &mut j);
    // the first element holding each load dof; a node's coordinates share it
    let holder = |dof: usize| {
        (0..sys.n_elements()).find(|&e| sys.element_dofs(e).contains(&dof)).expect("every coordinate is an element's")
    };
    let local = |k: usize, dof: usize| sys.block_dofs(k).iter().position(|&d| d == dof);
    for r in 0..nl {
        let e = holder(dofs[r]);
        for c in 0..nl {
            let v = j[c * nl + r];
            if v == 0.0 {
                continue;
            }
            let (row, col) = (dofs[r], dofs[c]);
            let slot = (local(e, row).zip(local(e, col)).map(|(ir, ic)| (e, ir, ic)))
                .or_else(|| (0..sys.n_blocks()).find_map(|k| Some((k, local(k, row)?, local(k, col)?))));
            let (k, ir, ic) = slot.expect("a load's Jacobian entry lies in an element or a coupling block");
            blocks[k][(ir, ic)] += factor * v;
        }
    }
}

/// `M` at `μ` as element blocks (each the file's times `ρ(μ)/ρ_file`), with the point
/// masses.
pub fn mass_blocks(sys: &FlexibleSystem, mu: &Parameters) -> Vec<Block> {
    let mut blocks: Vec<Block> =
        (0..sys.n_elements()).map(|e| sys.element(e).mass() * sys.mass_factor(e, mu)).collect();
    blocks.resize(sys.n_blocks(), Block::zeros());
    // point masses sit on their node's coordinates, in the block that holds them
    for (e, i, j, m) in sys.point_mass_entries() {
        blocks[e][(i, j)] += m;
    }
    blocks
}

/// `y = Σ_e P_eᵀ A_e P_e x`.
pub fn block_mul(sys: &FlexibleSystem, blocks: &[Block], x: &[f64], y: &mut [f64]) {
    y.iter_mut().for_each(|v| *v = 0.0);
    for (e, b) in blocks.iter().enumerate() {
        let d = sys.block_dofs(e);
        for j in 0..8 {
            let xj = x[d[j]];
            if xj == 0.0 {
                continue;
            }
            for i in 0..8 {
                y[d[i]] += b[(i, j)] * xj;
            }
        }
    }
}
