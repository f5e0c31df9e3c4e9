//! Which sparse Cholesky to use (issue "growth engine", item 5): one
//! numeric factorisation and one solve of an organ's Hessian, the work a
//! Newton iteration repeats, with the symbolic analysis done once outside
//! the timed loop for every candidate.
//!
//! - faer, supernodal, AMD ordering (what `NewtonSolver` uses);
//! - faer, simplicial, AMD ordering;
//! - nalgebra-sparse `CscCholesky::refactor`, natural ordering (it has no
//!   fill-reducing ordering of its own);
//! - nalgebra-sparse on the matrix permuted by faer's AMD ordering (the
//!   best it can do with help).
//!
//! Matrices: the Hessian of a lily-sized petal (14 x 28 = 392 particles)
//! and of a 4k-particle petal (45 x 90), springs stretched by a random
//! perturbation so both the spring and the hinge blocks are present.
//!
//! `cargo bench -p anthesis-physics --bench cholesky`

use anthesis_mesh::Topology;
use anthesis_mesh::generate::{jittered, test_petal};
use anthesis_physics::Elastic;
use anthesis_physics::pattern::BlockPattern;
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LltRef, SymbolicCholesky, SymmetricOrdering,
    factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};
use nalgebra_sparse::factorization::CscCholesky;
use nalgebra_sparse::na::DVector;
use nalgebra_sparse::{CooMatrix, CscMatrix};

/// An organ's regularised Hessian in the solver's upper CSC layout.
struct Hessian {
    pattern: BlockPattern,
    values: Vec<f64>,
}

impl Hessian {
    fn of_petal(columns: usize, rows: usize) -> Hessian {
        let mesh = test_petal(30.0, 12.0, columns, rows);
        let topology = match Topology::build(&mesh) {
            Ok(t) => t,
            Err(e) => panic!("test petal: {e}"),
        };
        let elastic = Elastic::at_rest(&mesh.positions, &topology);
        // A fixed pseudo-random perturbation of a tenth of an edge.
        let moved = jittered(&mesh.positions, 0.1 * 30.0 / rows as f64, 12345);
        let pattern = BlockPattern::new(moved.len(), elastic.coupled_pairs());
        let mut values = vec![0.0; pattern.nonzeros()];
        elastic.hessian(&moved, &[], &pattern, &mut values);
        // The solver's regularisation of the rigid motions.
        let mean = pattern.diagonal(&values).sum::<f64>() / pattern.dimension() as f64;
        pattern.add_to_diagonal(&mut values, 1e-6 * mean);
        Hessian { pattern, values }
    }

    fn structure(&self) -> SymbolicSparseColMatRef<'_, usize> {
        let n = self.pattern.dimension();
        SymbolicSparseColMatRef::new_checked(
            n,
            n,
            self.pattern.col_ptr(),
            None,
            self.pattern.row_idx(),
        )
    }

    fn rhs(&self) -> Vec<f64> {
        (0..self.pattern.dimension())
            .map(|i| ((i * 7919) % 101) as f64 / 101.0 - 0.5)
            .collect()
    }

    /// The full symmetric matrix for nalgebra-sparse, its rows and columns
    /// renumbered by `new_of_old`.
    fn full(&self, new_of_old: &[usize]) -> CscMatrix<f64> {
        let n = self.pattern.dimension();
        let mut triplets = Vec::with_capacity(2 * self.values.len());
        for col in 0..n {
            for idx in self.pattern.col_ptr()[col]..self.pattern.col_ptr()[col + 1] {
                let row = self.pattern.row_idx()[idx];
                let (r, c, v) = (new_of_old[row], new_of_old[col], self.values[idx]);
                triplets.push((r, c, v));
                if r != c {
                    triplets.push((c, r, v));
                }
            }
        }
        match CooMatrix::try_from_triplets_iter(n, n, triplets) {
            Ok(coo) => CscMatrix::from(&coo),
            Err(e) => panic!("triplets: {e}"),
        }
    }
}

/// faer's Cholesky with the symbolic analysis done once.
struct Faer {
    symbolic: SymbolicCholesky<usize>,
    factor: Vec<f64>,
    memory: MemBuffer,
}

impl Faer {
    fn new(hessian: &Hessian, threshold: SupernodalThreshold) -> Faer {
        let symbolic = match factorize_symbolic_cholesky(
            hessian.structure(),
            Side::Upper,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: threshold,
                ..Default::default()
            },
        ) {
            Ok(s) => s,
            Err(e) => panic!("symbolic: {e:?}"),
        };
        let scratch = symbolic
            .factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default())
            .or(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
        Faer {
            factor: vec![0.0; symbolic.len_val()],
            memory: MemBuffer::new(scratch),
            symbolic,
        }
    }

    fn factor_and_solve(&mut self, hessian: &Hessian, x: &mut [f64]) {
        let matrix = SparseColMatRef::new(hessian.structure(), &hessian.values);
        if let Err(e) = self.symbolic.factorize_numeric_llt(
            &mut self.factor,
            matrix,
            Side::Upper,
            LltRegularization::default(),
            Par::Seq,
            MemStack::new(&mut self.memory),
            Default::default(),
        ) {
            panic!("faer factorisation: {e:?}");
        }
        let n = x.len();
        LltRef::new(&self.symbolic, &self.factor).solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(x, n, 1),
            Par::Seq,
            MemStack::new(&mut self.memory),
        );
    }
}

fn cholesky(c: &mut Criterion) {
    let mut group = c.benchmark_group("factor_and_solve");
    group.sample_size(10);
    for (name, columns, rows) in [("lily_petal_392", 14, 28), ("petal_4k", 45, 90)] {
        let hessian = Hessian::of_petal(columns, rows);
        let rhs = hessian.rhs();
        let n = rhs.len();

        let mut supernodal = Faer::new(&hessian, SupernodalThreshold::FORCE_SUPERNODAL);
        let mut reference = rhs.clone();
        supernodal.factor_and_solve(&hessian, &mut reference);
        group.bench_function(BenchmarkId::new("faer_supernodal_amd", name), |b| {
            let mut x = rhs.clone();
            b.iter(|| {
                x.copy_from_slice(&rhs);
                supernodal.factor_and_solve(&hessian, &mut x);
            })
        });

        let mut simplicial = Faer::new(&hessian, SupernodalThreshold::FORCE_SIMPLICIAL);
        group.bench_function(BenchmarkId::new("faer_simplicial_amd", name), |b| {
            let mut x = rhs.clone();
            b.iter(|| {
                x.copy_from_slice(&rhs);
                simplicial.factor_and_solve(&hessian, &mut x);
            })
        });

        let natural: Vec<usize> = (0..n).collect();
        let amd: Vec<usize> = match supernodal.symbolic.perm() {
            // `arrays` gives (old of new, new of old).
            Some(perm) => perm.arrays().1.to_vec(),
            None => natural.clone(),
        };
        for (ordering, new_of_old) in [("natural", &natural), ("amd", &amd)] {
            let matrix = hessian.full(new_of_old);
            let mut factor = match CscCholesky::factor(&matrix) {
                Ok(f) => f,
                Err(e) => panic!("nalgebra-sparse: {e}"),
            };
            let mut permuted_rhs = DVector::zeros(n);
            for (old, &new) in new_of_old.iter().enumerate() {
                permuted_rhs[new] = rhs[old];
            }
            // Same answer as faer's, or the comparison means nothing.
            let x = factor.solve(&permuted_rhs);
            for (old, &new) in new_of_old.iter().enumerate() {
                let scale = reference.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                assert!(
                    (x[new] - reference[old]).abs() <= 1e-6 * scale,
                    "nalgebra-sparse and faer disagree at {old}"
                );
            }
            group.bench_function(
                BenchmarkId::new(format!("nalgebra_sparse_{ordering}"), name),
                |b| {
                    b.iter(|| {
                        if let Err(e) = factor.refactor(matrix.values()) {
                            panic!("nalgebra-sparse: {e}");
                        }
                        factor.solve(&permuted_rhs)
                    })
                },
            );
        }
    }
    group.finish();
}

criterion_group!(benches, cholesky);
criterion_main!(benches);
