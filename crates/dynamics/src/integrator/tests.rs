//! The registered tableaux against the Runge–Kutta order conditions (Butcher 2016, Sec. 31:
//! a method has order p iff Σ_i b_i Φ_i(t) = 1/γ(t) for every rooted tree t with |t| ≤ p), with
//! the trees generated here, so a mistyped coefficient fails.

use nalgebra::Vector3;

use super::{by_name, names_for_message, MAX_STAGES, METHODS, RK4, RK8};

/// A rooted tree as the sorted list of its root's subtrees (indices into the tree list).
#[derive(Debug, Clone)]
struct Tree {
    order: usize,
    children: Vec<usize>,
}

/// Every rooted tree with at most `max_order` vertices, ordered by order (1, 1, 2, 4, 9, 20, 48,
/// 115, 286 trees of orders 1…9; OEIS A000081). A tree of order n is a root plus a multiset of
/// smaller trees whose orders sum to n − 1, enumerated as non-increasing index sequences so each
/// multiset appears once.
fn rooted_trees(max_order: usize) -> Vec<Tree> {
    let mut trees = vec![Tree {
        order: 1,
        children: vec![],
    }];
    for n in 2..=max_order {
        let smaller = trees.len();
        let mut new = Vec::new();
        // Depth-first over non-increasing child index sequences with total order n − 1.
        let mut stack: Vec<(Vec<usize>, usize, usize)> = vec![(vec![], n - 1, smaller)];
        while let Some((kids, left, max_idx)) = stack.pop() {
            if left == 0 {
                new.push(Tree {
                    order: n,
                    children: kids,
                });
                continue;
            }
            for (idx, t) in trees[..max_idx].iter().enumerate() {
                if t.order <= left {
                    let mut k = kids.clone();
                    k.push(idx);
                    stack.push((k, left - t.order, idx + 1));
                }
            }
        }
        trees.extend(new);
    }
    trees
}

/// Largest |Σ b_i Φ_i(t) − 1/γ(t)| over the trees of order exactly `order`.
fn order_residual(a_rows: &[&[f64]], b: &[f64], trees: &[Tree], order: usize) -> f64 {
    let s = b.len();
    let a = |i: usize, j: usize| a_rows[i].get(j).copied().unwrap_or(0.0);
    // Φ_i(t) per tree, and γ(t).
    let mut phi: Vec<Vec<f64>> = Vec::with_capacity(trees.len());
    let mut gamma: Vec<f64> = Vec::with_capacity(trees.len());
    for t in trees {
        let mut p = vec![1.0; s];
        let mut g = t.order as f64;
        for &u in &t.children {
            for (i, pi) in p.iter_mut().enumerate() {
                *pi *= (0..s).map(|j| a(i, j) * phi[u][j]).sum::<f64>();
            }
            g *= gamma[u];
        }
        phi.push(p);
        gamma.push(g);
    }
    trees
        .iter()
        .enumerate()
        .filter(|(_, t)| t.order == order)
        .map(|(k, _)| {
            let sum: f64 = b.iter().zip(&phi[k]).map(|(b, p)| b * p).sum();
            (sum - 1.0 / gamma[k]).abs()
        })
        .fold(0.0, f64::max)
}

/// Round-off bound for the order sums of the published (rational, ~18-digit) coefficients in
/// f64: the RK8 sums add terms up to ~20 in size, so a few 1e-15 of absolute error is
/// expected; a mistyped digit in a 10-digit numerator moves a sum by ≥ ~1e-10.
const ORDER_TOL: f64 = 1e-12;

#[test]
fn tree_counts_match_a000081() {
    let trees = rooted_trees(9);
    let counts: Vec<usize> = (1..=9)
        .map(|n| trees.iter().filter(|t| t.order == n).count())
        .collect();
    assert_eq!(counts, [1, 1, 2, 4, 9, 20, 48, 115, 286]);
}

#[test]
fn every_method_has_exactly_its_order() {
    let trees = rooted_trees(9);
    for m in METHODS {
        for p in 1..=m.order as usize {
            let r = order_residual(m.a, m.b, &trees, p);
            assert!(
                r < ORDER_TOL,
                "{}: order-{p} conditions off by {r:e}",
                m.name
            );
        }
        // And not one more: the checker sees the order, it does not just pass.
        let r = order_residual(m.a, m.b, &trees, m.order as usize + 1);
        assert!(
            r > 1e-6,
            "{}: order {} conditions hold too ({r:e})",
            m.name,
            m.order + 1
        );
    }
}

#[test]
fn a_mistyped_rk8_coefficient_breaks_the_order_conditions() {
    // Negative control: a_10,4 with one digit changed in its 10th significant figure.
    let trees = rooted_trees(8);
    let mut rows: Vec<Vec<f64>> = RK8.a.iter().map(|r| r.to_vec()).collect();
    rows[10][3] *= 1.0 + 1e-9;
    let rows: Vec<&[f64]> = rows.iter().map(Vec::as_slice).collect();
    let worst = (1..=8)
        .map(|p| order_residual(&rows, RK8.b, &trees, p))
        .fold(0.0, f64::max);
    assert!(worst > ORDER_TOL, "perturbation not detected ({worst:e})");
}

#[test]
fn tableaux_are_well_formed() {
    for m in METHODS {
        let s = m.stages();
        assert!(s <= MAX_STAGES, "{}: {s} stages > MAX_STAGES", m.name);
        assert_eq!(m.c.len(), s, "{}", m.name);
        assert_eq!(m.a.len(), s, "{}", m.name);
        assert_eq!(m.c[0], 0.0, "{}: the first stage is at t0", m.name);
        for (i, row) in m.a.iter().enumerate() {
            assert_eq!(
                row.len(),
                i,
                "{}: row {i} must be strictly lower-triangular",
                m.name
            );
            if i > 0 {
                assert!(
                    row.iter().any(|&a| a != 0.0),
                    "{}: row {i} is empty",
                    m.name
                );
            }
            // The stage-time convention c_i = Σ_j a_ij (so dynamic effectors see the right t).
            let sum: f64 = row.iter().sum();
            assert!(
                (sum - m.c[i]).abs() < 1e-14,
                "{}: row {i} sums to {sum}, c = {}",
                m.name,
                m.c[i]
            );
        }
        assert_eq!(by_name(m.name), Some(*m));
    }
    let names: Vec<&str> = METHODS.iter().map(|m| m.name).collect();
    let mut unique = names.clone();
    unique.dedup();
    assert_eq!(names, unique, "method names must be unique");
    assert_eq!(names[0], "rk4", "RK4 is listed first (it is the default)");
    assert_eq!(names_for_message(), "\"rk4\" or \"rk8\"");
    assert_eq!(by_name("rk5"), None);
}

#[test]
fn rk4_combination_is_the_historical_expression() {
    // The exact expressions flexdyn's RK4 has always used (bit-identity of existing runs).
    let k = [
        Vector3::new(0.1, -2.0 / 3.0, 1e-300),
        Vector3::new(1.0 / 7.0, 3.3, -4.4e12),
        Vector3::new(-0.9, 2.0f64.sqrt(), 5.5),
        Vector3::new(1.0 / 3.0, -1e-9, 7.25),
    ];
    let h = 0.001;
    let want = (k[0] + (k[1] + k[2]) * 2.0 + k[3]) * (h / 6.0);
    assert_eq!(RK4.combine_vec3(&k, h), want);
    for (c, want_c) in want.iter().enumerate() {
        let s = RK4.combine(|i| k[i][c], h);
        let want_scalar = h / 6.0 * (k[0][c] + 2.0 * (k[1][c] + k[2][c]) + k[3][c]);
        assert_eq!(s.to_bits(), want_scalar.to_bits());
        assert_eq!(s.to_bits(), want_c.to_bits());
    }
}

#[test]
fn weighted_combination_integrates_polynomials_to_the_method_order() {
    // y′ = t^q, y(0) = 0, one step of h: exact h^{q+1}/(q+1) for q < order (the bushy trees).
    for m in METHODS {
        let h = 0.5;
        for q in 0..m.order as i32 {
            let got = m.combine(|i| (m.c[i] * h).powi(q), h);
            let want = h.powi(q + 1) / (q as f64 + 1.0);
            assert!(
                (got - want).abs() < 1e-14,
                "{} q={q}: {got} vs {want}",
                m.name
            );
        }
    }
}
