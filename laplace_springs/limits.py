"""Every size, tolerance, clustering gap and safety factor of the package, in one place.

The modules read these values through :func:`limits` when they use them (never at import
time), so a test or a user can run under other limits with :func:`using_limits`::

    >>> from laplace_springs.limits import limits, using_limits
    >>> limits().certified_max_order
    120
    >>> with using_limits(certified_max_order=8):
    ...     limits().certified_max_order
    8

Each field says what it limits and the measurement behind its value (one core of the
2-core development machine unless said). A value of the package's limits that a request
exceeds is a :class:`~laplace_springs.model.errors.LimitError` naming the field.
"""

from __future__ import annotations

import contextlib
import dataclasses
import threading
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

__all__ = ["Limits", "limits", "using_limits", "DEFAULT_LIMITS"]


@dataclass(frozen=True)
class Limits:
    """The package's limits and tolerances (see the module notes)."""

    # -- the result contract ------------------------------------------------------------
    #: Default accuracy of every evaluation, relative to max(‖x(t)‖∞, S₀).
    target: float = 1e-13
    #: A float64 bound never claims less than this relative to the value (14 significant
    #: digits): a decimal reference printed to 15 digits differs from a correctly rounded
    #: float64 value by up to 5e-15 of it, and no float64 value is better than its decimal.
    min_relative_bound: float = 1e-14
    #: Decimal digits of an escalated float64 evaluation on the exact route.
    escalation_digits: int = 20
    #: Largest number of decimal digits ``evaluate(..., dps=)`` accepts.
    max_dps: int = 10_000
    #: Largest number of values (times x coordinates) one evaluation returns at once; more
    #: are refused with the way out (evaluate in chunks). 10⁸ float64 values are 800 MB,
    #: and an engine holds a few arrays of that size while it works.
    max_evaluation_values: int = 50_000_000
    #: Largest number of times one evaluation takes (10⁷ times: 80 MB per coordinate).
    max_times: int = 20_000_000
    #: Largest number of values (times x coordinates) one engine call computes: longer
    #: evaluations are done in chunks of times (memory bounded, progress shown, Ctrl-C
    #: honoured between chunks). An engine holds a few arrays of this size (16 MB each).
    evaluation_chunk_values: int = 2_000_000
    #: An evaluation the plan expects to take longer than this (seconds) shows progress.
    progress_after_seconds: float = 2.0

    # -- the planner: which engine serves a scene -----------------------------------------
    #: Largest scene the tiny engine (closed-form float64 poles with a residual bound)
    #: takes: its 2n x 2n eigenproblem is cheaper than python-control's set-up up to here.
    tiny_max_coordinates: int = 4
    #: Largest magnitude (its reciprocal the smallest nonzero one) of an entry of M⁻¹K,
    #: M⁻¹C and the initial data the tiny engine takes: its closed forms square and
    #: multiply them (the discriminant c²/4m², the initial acceleration and jerk), which
    #: must stay inside float64's range (1e±308). Beyond it (a mass of 1e-300 on a spring
    #: of 1e300) the certified and exact engines serve.
    tiny_max_magnitude: float = 1e100
    #: Largest scene the exact route serves as a fallback or escalation (symbolic work
    #: grows fast with the degree of Δ's irreducible factors).
    exact_fallback_max_coordinates: int = 8
    #: Largest scene whose ``x`` is built as an exact closed form on other routes; beyond it
    #: ``x`` is the modal form with Float coefficients.
    exact_form_max_coordinates: int = 8
    #: Largest free scene with rational entries whose ``x`` is built as an exact closed form
    #: on other routes: its Δ's large factors are written in named numbers
    #: (exact/named_roots.py), damped chains of unequal masses in about 1 s at 12 and 16
    #: coordinates (solve, x and five values), 4.3 s at 40.
    exact_named_form_max_coordinates: int = 16
    #: Largest scene whose ``x`` on a numeric route is a SymPy column (Float coefficients);
    #: beyond it a ModalForm: 12 rows of 24 terms are still readable, 200 rows of 400 not.
    closed_form_max_coordinates: int = 12
    #: Largest first-order size (2n) the certified route takes: its roots cost about 1 s at
    #: degree 100 and grow like the cube of the degree.
    certified_max_order: int = 120
    #: Largest scene (coordinates) the general (non-symmetric) modal route takes: it holds
    #: M, C, K densely and decomposes the 2n x 2n first-order matrix four times (the motion
    #: and three perturbed copies for its bound). Damped chains: 200 coordinates 1 s, 400
    #: 6 s, 800 31 s; time grows like n³, memory like n².
    general_modal_max_coordinates: int = 1_000
    #: Largest undamped or classically damped scene the symmetric eigen route takes: the
    #: n x n shapes (128 MB at 4,000). Also the largest scene whose shapes a Chebyshev
    #: motion builds on request.
    classical_max_coordinates: int = 4_000
    #: Largest scene whose eigenvalues (``poles``) a Chebyshev motion computes densely when
    #: K is not banded.
    dense_eigenvalues_max_coordinates: int = 4_000
    #: Largest scene the Chebyshev route takes (the scene files' limit).
    chebyshev_max_coordinates: int = 100_000
    #: Largest number of floats of Chebyshev vectors held at once (1 GB): n·(N+1) per
    #: initial vector, N ≈ t_max·√‖M⁻¹K‖/2 + a few dozen.
    chebyshev_max_vector_floats: int = 125_000_000
    #: Largest growth e^{μ·t_max} the Chebyshev route accepts when its verified interval of
    #: M⁻¹K reaches below 0 (K not proved positive definite): its bound is about u times
    #: that growth of the data, 2e-13 at 1e3 (measured: a dense K = BBᵀ + 100·I of 100
    #: masses, Gershgorin down to −8,791, gave a bound of 2.6e27 at t = 1).
    chebyshev_max_growth: float = 1e3
    #: Largest number of Taylor steps one krylov evaluation takes (its cost grows linearly
    #: with the last time: about 2·t·ν steps).
    krylov_max_steps: int = 200_000
    #: Largest H·ν of a krylov step. Longer steps take fewer products per unit of time
    #: (sparse products per unit of t·ν, chains and meshes of 1,000 to 10,000 masses: 13.4
    #: at θ = 4, 11.9 at 5, 10.9 at 6) but values inside a step are float64 sums of terms
    #: that cancel by up to e^θ: a 10,000-mass mesh's bound at t = 50 is 1.3e-14 of the
    #: scale at 4, 4.4e-14 at 5, and at 8 a 4,000-mass mesh's is 2.9e-13.
    krylov_step_norm: float = 5.0
    #: Largest rounding and truncation one krylov step may add, relative to the scene's
    #: energy N(z0): terms are formed to about 2^-70 (double-double) until a float64
    #: product's rounding, carried to the end of the step, falls below this. 2^-58 over the
    #: 24 to 73 steps of t = 50 stays below the values' own rounding (4e-15 to 4e-14 of
    #: the scale) and takes about 2 double-double terms fewer per step than 2^-60.
    krylov_step_error: float = 2.0**-58
    #: Largest X = ν_c·H of a long Bessel step of the krylov engine (its Chebyshev path for
    #: scenes held by the ground; 0 turns it off): 160 products a step at 96, 121 of them
    #: in double-double (122 and 87 at 64; the 4,000-mass mesh of bench_krylov 8% faster
    #: at 96, the 1,000-mass one 2% slower).
    krylov_bessel_norm: float = 96.0
    #: Largest d·H of a Bessel step (d ≥ ‖M^{-1/2}CM^{-1/2}‖): its terms grow about like
    #: e^{d·H} at worst, and so do the bounds on their rounding (at 6 a random 6-mass
    #: network of tests/numeric/test_krylov.py took X = 38 and a bound of 1.5e-13, against
    #: Taylor's 6.5e-16).
    krylov_bessel_growth: float = 4.0
    #: Shortest X of a Bessel step: below it, Taylor's steps (fewer products per term's
    #: double-double split) are about as cheap.
    krylov_bessel_min_norm: float = 32.0
    #: The Bessel steps' shift δ as a fraction of d/2 (d ≥ ‖M^{-1/2}CM^{-1/2}‖). 1 centres
    #: the field of values' real range, but most modes of a lightly damped network sit near
    #: the imaginary axis and the shift moves them off it: on the meshes of bench_krylov
    #: δ = 0 was 5-7% faster with bounds 1.2e-14 against 1.3e-14 (4,000 masses) and 1.4e-14
    #: against 6.9e-14 (10,000).
    krylov_bessel_shift: float = 0.0
    #: Most float64 numbers the krylov engine keeps as checkpoints of its march (each step's
    #: starting state, 4n numbers): later calls restart from the nearest one (256 MB).
    krylov_checkpoint_floats: int = 32_000_000
    #: Largest scene (coordinates) the exact route takes. The fraction-free adjugate of
    #: λ²M + λC + K costs about n⁴ (damped chains: 12 coordinates 0.7 s, 20 3 s, 30 14 s).
    max_exact_coordinates: int = 40
    #: Largest degree of an irreducible rational factor whose exact real terms are written
    #: out (forced scenes, inverse transforms): cost grows like d⁴ (16: 0.4 s, 24: 1.2 s,
    #: 40: 10 s). A free scene with rational entries names its roots instead (any degree,
    #: up to max_exact_coordinates: damped chains of 16 masses, degree 32, 0.3 s; 40
    #: masses, degree 80, 4 s).
    max_exact_factor_degree: int = 24
    #: Most distinct irrational numbers (π, e, √5, ∛2: the atoms of the entries of M, C, K)
    #: a numeric scene's exact terms are written in, where the planner chooses: √5 − 1, e
    #: and π/3 on one forced mass took 20 s to a coefficient of 180,000 characters, √2 and
    #: π on one free mass 0.2 s to 174 (the numeric engines serve the first; method="exact"
    #: and ``x`` still build it).
    max_exact_irrationals: int = 2
    #: Above this degree, an irreducible rational factor that needs CRootOf gives a motion in
    #: named numbers (ρ_j, α_j, β_j, c_j from flint, CRootOf built when asked:
    #: laplace_springs/exact/named_roots.py); up to it, coefficients written out as
    #: polynomials in re/im of CRootOf. SymPy numbers the roots of q in 0.34 s at degree 8,
    #: 2.4 s at 16, 10 s at 24; the written-out form has about d²/4 terms per coefficient.
    exact_expanded_max_degree: int = 4
    #: Largest work of numbering the roots of one irreducible rational factor with SymPy's
    #: CRootOf (k² x D x b: k roots off the real line, D bisections, b bits of its
    #: coefficients; laplace_springs/exact/isolation.py) whose terms are written out:
    #: 1.5e-6 to 2e-5 s a unit (masses of 1 with a dashpot of 1e-30: 1.7e5, 1.1 s; masses
    #: of 1e-100 with a dashpot of 1e-100: 1.8e6, 15 s; masses of 1e-300 with a dashpot of
    #: 1e-300: 1.6e7, more than 300 s). Entries of ordinary scales stay far below (2 g
    #: masses on 2e9 N/m springs, a dashpot of 0.35 N·s/m: 2e4). Above it, a free scene
    #: with rational entries names its roots (any degree, flint: milliseconds).
    exact_expanded_max_isolation: int = 200_000
    #: Largest such work the exact route takes where roots cannot be named (forced scenes,
    #: inverse transforms, the g-basis of a forced scene): 3 to 15 s. Beyond it the
    #: factor is refused with the scene's smallest and largest entries named (the motion
    #: itself spans those scales, a frequency of 1e150 against a decay rate of 0.1: other
    #: units do not bring them closer).
    max_exact_isolation: int = 2_000_000
    #: ``modes`` is exact up to this many coordinates for rational scenes.
    modes_exact_max_coordinates: int = 40
    #: Up to this many coordinates, ``modes`` of a scene with irrational entries decides
    #: exactly which clustered float eigenvalues are one multiple root (the squarefree
    #: decomposition of Δ over QQ<√2>-like fields: Δ itself takes 0.05 s at 4 coordinates,
    #: 0.5 s at 8, and is refused by max_resolvent_terms at 12 on two √2 chains).
    modes_multiple_root_max_coordinates: int = 8
    #: Up to this many coordinates the text summary takes the exact modes.
    exact_modes_max_coordinates: int = 8
    #: Times at which "auto" checks the modal route's own bound before it keeps it.
    probe_times: tuple[float, ...] = (0.0, 1.0)
    #: Smallest scene the numeric forced route ("exo") takes: below it exact partial
    #: fractions give closed forms in seconds (measured: a chain of 12 masses with one
    #: dashpot and cos(2t), solve and 11 times, 17 s exact, 0.6 s exo; 30 masses: the exact
    #: route refuses, a degree-60 factor of Δ).
    exo_min_coordinates: int = 9
    #: Up to this size the exo engine chooses the engine of a piece's free part for a
    #: tenth of the target (the free and particular parts cancel where a forced motion
    #: starts from rest); beyond, for the target, and a time is recomputed by the next
    #: engine only when its bound misses ten times the target (the certified engine
    #: takes 2 to 4.5 s to build at 50 masses: a chain driven by cos 2t, 100 times,
    #: 2.1 s -> 0.08 s with a bound of 4e-13 of the scale).
    exo_fine_max_coordinates: int = 16
    #: Most periods of a periodic force the numeric forced route sums for one evaluation
    #: (each period is one more evaluation of its piece at the shifted times).
    exo_max_periods: int = 20_000
    #: A value whose error bound, after every engine of the plan has tried, still exceeds
    #: max(target, this) times the contract's scale is refused (a LimitError naming the
    #: way out), with or without ``return_error``: no value off by more than 1e-10 of the
    #: scale leaves the package, whatever the call.
    refusal_bound: float = 1e-10

    # -- numerical tolerances of the engines ---------------------------------------------
    #: Eigenvalue condition number above which a mode of the general modal route is
    #: treated inside a block.
    kappa_max: float = 1e3
    #: Poles closer than this, relative to the largest |pole| (‖Z‖ for the modal route),
    #: are one cluster on every engine: their individual eigenvectors (or residues) are
    #: not determined in float64, their invariant subspace (divided differences) is.
    close_poles: float = 1e-6
    #: Largest number of eigenvalues grouped around one ill-conditioned eigenvalue.
    max_group: int = 8
    #: Factor applied to the modal route's first-order error bound (no sampling).
    modal_safety: float = 8.0
    #: Factor applied to the modal route's sampled sensitivity (max of the perturbed
    #: decompositions).
    sample_safety: float = 8.0
    #: Perturbed decompositions the modal route measures per scene.
    samples: int = 3
    #: Largest first-order size for which an unseparable group falls back to one block.
    whole_block_max: int = 64
    #: Condition number of the mass block beyond which float64 cannot hold the scene.
    max_mass_condition: float = 1e14
    #: Condition number of the dashpot block of massless nodes beyond which float64 cannot
    #: hold the reduction.
    max_damping_condition: float = 1e12
    #: Largest half-bandwidth of K (diagonal M) solved with scipy's banded eigensolver.
    banded_max_bandwidth: int = 32
    #: Largest scene with a non-diagonal M whose classical damping is checked exactly.
    dense_check_max_coordinates: int = 64
    #: Up to this many coordinates all the poles of a krylov scene are computed densely.
    dense_poles_max_coordinates: int = 200
    #: Largest scene the refined (long-horizon) engine takes: it holds the n x n shapes as
    #: double-doubles and refines them with n x n float64 products. Uniform chains,
    #: decomposition and refinement: 200 masses 0.3 s, 1,000 2.2 s, 4,000 54 s and 2.7 GB
    #: (the time grows like n³, the memory like n²).
    refined_max_coordinates: int = 4_000
    #: Largest n·(nonzeros of M, C, K) of a sparse refined scene: its double-double products
    #: take ≈ 6e-8 s per unit and about five are made, so 2e8 is about a minute (a
    #: 4,000-mass chain is 6.4e7).
    refined_max_products: int = 200_000_000
    #: Largest dense K (rows wider than 2·banded_max_bandwidth + 1) the refined engine
    #: takes: its products with K are 13 float64 n x n products each (error-free slices),
    #: ≈ 58 in all; 1,000 coordinates ≈ 10 s, 2,000 ≈ 1 min (reading 4 million entries
    #: included).
    refined_dense_max_coordinates: int = 2_000
    #: Highest derivative order the refined engine bounds (each order multiplies the
    #: initial-data term of its bound by about ‖M⁻¹K‖).
    refined_max_order: int = 4
    #: Refinement steps at most (each: two n x n float64 products). From float64 pairs
    #: the residuals reach the double-double level in 2–3 steps; more only for clusters
    #: whose eigenvalues differ by less than their float64 error.
    refined_max_steps: int = 6
    #: Largest cluster (frequencies closer than close_poles) diagonalised as one block at
    #: 40 digits by mpmath: ≈ k³ multiprecision operations, 2 ms at k = 2, ≈ 7 s at k = 48.
    #: A larger cluster is diagonalised in pieces (exact for a repeated eigenvalue; for
    #: distinct ones its residuals stay at float64's level and the bound grows with t).
    refined_max_cluster: int = 48
    #: Modes summed in float64 per block of x = Φq before the blocks' compensated sum: the
    #: rounding bound γ_b = 3.6e-15 of Σ|φ||q| at b = 32 stays below the target.
    refined_sum_block: int = 32
    #: A pole-sum block is used while t·(its link heights) ≤ this.
    block_theta: float = 1.0
    #: Merge two pole groups when their separate forms exceed the joint form by this.
    block_gain: float = 16.0
    #: Largest pole group evaluated as one block (Newton data costs O(M²n)).
    max_block: int = 24
    #: Highest working precision (bits) of the certified route's ball evaluation.
    max_bits: int = 1 << 15
    #: Largest number of segments the sampled route's mpmath evaluation runs through.
    mp_max_segments: int = 20_000
    #: Largest number of distinct step lengths the sampled mpmath evaluation exponentiates.
    mp_max_steps: int = 64
    #: A sample grid is uniform when every step is within this fraction of 1/‖A‖ of its
    #: nominal length (then the second-order remainder is < ε).
    uniform_grid: float = 1e-8
    #: Largest ratio between a common period and one input's period.
    max_period_ratio: int = 256
    #: Largest power of z = e^{-us} written for commensurate delays with common unit u.
    max_delay_power: int = 512

    # -- sweeps -------------------------------------------------------------------------
    #: Largest scene the sweep compiles symbolically (the symbolic adjugate grows fast).
    sweep_max_coordinates: int = 8
    #: Roots closer than this · (largest |root|) are one cluster in the sweep kernels
    #: (evaluated by divided differences; the close-poles rule of kernels/poles.py with a
    #: wider gap: a double root from a float64 companion matrix is known to about √ε).
    cluster_gap: float = 5e-2
    #: Memory a sweep chunk's largest array may take (bytes).
    chunk_bytes: int = 32 * 2**20
    #: Estimated seconds of work in one sweep chunk (one Dask task): long enough that a
    #: task's overhead (~2 ms on a LocalCluster) is below 1 %, short enough that a lost
    #: worker costs little and progress moves (chunks are cut by estimated cost, not count).
    sweep_chunk_seconds: float = 1.0
    #: Most parameter sets one sweep (or ``sample_parameters``) takes: 10⁸ sets of three
    #: parameters are 2.4 GB of float64 before any motion is computed; more are refused
    #: with the way out (sweep in parts, streaming to a store).
    sweep_max_sets: int = 100_000_000

    # -- input ------------------------------------------------------------------------
    #: Most coordinates (masses) a scene may have (a 100,000-mass chain loads in ~30 s).
    max_coordinates: int = 100_000
    #: Most components (springs and dashpots together) a scene may have.
    max_components: int = 300_000
    #: Largest n of an n x n matrix given entry by entry (three 500 x 500 arrays load in 9 s).
    max_matrix_input_size: int = 500
    #: Most terms one equation of motion (Scene.from_equations) may expand into, estimated
    #: from the expression before SymPy expands it. Measured on one core: a product of sums
    #: expanding to 2,000 terms takes 0.7 s, 5,000 terms 2.4 s, 11,000 terms 5.5 s;
    #: (k0 + ... + k29)**12 * x'' (7·10⁹ terms) ran out of memory after 30 s, and is now
    #: refused in a millisecond.
    max_equation_terms: int = 5_000
    #: Largest number of terms the symbolic resolvent may form when it expands
    #: det(λ²M + λC + K) and its adjugate, bounded before expanding (the permanent of the
    #: entries' expanded sizes, which counts the Leibniz products). A fully symbolic damped
    #: chain of four masses bounds 941 terms and solves in 2 s; K = (k0 + ... + k9)**40
    #: (2·10⁹ terms) ran past 60 s and is refused at once.
    max_resolvent_terms: int = 100_000
    #: Scenes with at most this many coordinates store M, C, K densely.
    dense_storage_max_coordinates: int = 256
    #: Longest text accepted by the parser, in characters.
    max_expression_length: int = 10_000
    #: Deepest nesting of parentheses, calls, signs and powers accepted.
    max_nesting_depth: int = 100
    #: Largest decimal exponent of a number literal.
    max_literal_exponent: int = 4_000
    #: Most significant digits of a number (literal, numerator or denominator).
    max_digits: int = 1_000
    #: Largest scene file, in bytes (about 4 times a 100,000-mass chain).
    max_file_bytes: int = 16 * 2**20
    #: Largest CSV file read (about 2 million rows of two numbers).
    max_csv_bytes: int = 64 * 2**20
    #: Most declared parameters of a scene ([parameters] in a scene file, parameters=...):
    #: declaring costs about 3 µs each (10⁴ load in 0.3 s, 10⁶ took over 20 s), and no
    #: symbolic solve uses more than a few dozen.
    max_parameters: int = 10_000
    #: Most samples of one sampled force history (ls.sampled, a CSV column): 16 bytes each.
    #: One mass, 100 s of data: 10⁶ samples solve and evaluate in 12 s, 10⁷ in 62 s.
    max_samples: int = 2_000_000
    #: Most atoms c·t^k·e^{zt} a forcing entry may expand into (a cosine counts 2, a step
    #: 2), estimated from the expression before it is expanded (model/forcing_size.py).
    #: Measured on one mass, exact route: 128 cosines of distinct frequencies (256) build in
    #: 0.7 s and solve in 1.2 s, 256 cosines in 3.7 s and 11 s; 10⁴ are refused in 0.5 s.
    max_forcing_terms: int = 256
    #: Highest power of t in a forcing entry. t³² builds in 0.2 s and solves in 0.6 s,
    #: t¹⁰⁰ solves in 4.6 s, t¹⁰⁰⁰ in minutes; from about t²⁰ on, the response's
    #: polynomial terms cancel in float64 and its values need the mp engine.
    max_forcing_degree: int = 32
    #: Largest power k of a factor (s − a)^k or q(s)^k of a transform given to
    #: ``ls.inverse_laplace`` (read from its product as given): 1/s**128 inverts in 1.3 s,
    #: 1/s**300 in 16 s, 1/s**1000 ran for minutes.
    max_pole_multiplicity: int = 128
    #: Most switching times (steps, impulses, delayed pieces) of one forcing entry: each
    #: one is one more exact solve of the scene (measured per switching time: 10 ms for
    #: one mass, 0.15 s for 4 masses, 2–3 s for an 8-mass damped chain).
    max_forcing_delays: int = 32
    #: Most irrational or symbolic constants (parameters, phases cos(1/2), √2, e³) in the
    #: terms of one forcing entry: each is one more variable of every polynomial the exact
    #: solve forms. 12 cosines with distinct phases build and solve in 3.5 s (one mass),
    #: 16 in 13 s, 24 in 30 s.
    max_forcing_constants: int = 12

    # -- output: animations, worked-example pages, the explorer ----------------------------
    #: Most masses an animation draws; a larger scene animates a chosen subset (by default
    #: this many, evenly spaced). Beyond about 12 blocks a diagram in a 9-inch-wide figure
    #: has labels under 6 points.
    animation_max_masses: int = 12
    #: Most frames of one animation (a 12-second clip at 25 frames per second): each frame
    #: is a PNG of 20-60 kB in an inline (to_jshtml) animation.
    animation_max_frames: int = 300
    #: Most pixels of one animation frame (the figure's size in inches times dpi, squared):
    #: the 9 x 6.5 inch figure renders 0.37 Mpx (80 dpi) in 0.22 s a frame, 2.3 Mpx (200
    #: dpi) in 0.53 s, 9.4 Mpx (400 dpi) in 1.7 s; dpi = 1e9 failed inside matplotlib.
    animation_max_frame_pixels: int = 4_000_000
    #: Most parameter sets a worked-example page precomputes for its sliders (each set is
    #: n x 121 float32 values in base64, about 650 bytes per coordinate in the page).
    page_max_grid_sets: int = 400
    #: Accuracy of the curves the explorer and the pages' sliders draw, relative to
    #: max(‖x(t)‖∞, S₀): 1e-8 is far below a pixel (1e-3). At the default target the sweep
    #: kernel's estimate near a drive within its cluster gap of a lightly damped mode (about
    #: 1e-10, measured on Example 5 with ω = 18) sends the set to the exact solver: 0.4 s
    #: instead of 16 ms a move.
    explore_target: float = 1e-8
    #: Most samples of a page's plot: a stiff scene (ω = 1414 on Example 1 with k = 10⁶) asked
    #: for 200,000 and took 18 s to draw; beyond this the page plots a shorter span.
    page_max_plot_samples: int = 20_000


#: The limits the package ships with.
DEFAULT_LIMITS = Limits()

class _State(threading.local):
    """The limits in force in each thread (a class attribute: the defaults in every thread
    until :func:`using_limits` sets its own, read without a failed lookup)."""

    current: Limits = DEFAULT_LIMITS


_STATE = _State()


def limits() -> Limits:
    """The limits in force (the defaults unless :func:`using_limits` is active)."""
    return _STATE.current


@contextlib.contextmanager
def using_limits(**changes: Any) -> Iterator[Limits]:
    """Run a block under other limits (this thread only).

    Raises
    ------
    TypeError
        For a name that is not a field of :class:`Limits`.

    Examples
    --------
    >>> with using_limits(max_coordinates=10) as lim:
    ...     lim.max_coordinates
    10
    """
    previous = limits()
    _STATE.current = dataclasses.replace(previous, **changes)
    try:
        yield _STATE.current
    finally:
        _STATE.current = previous
