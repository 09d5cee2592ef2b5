"""Stage 2, exact: the resolvent Δ(λ), adj(λ), partial fractions over ℚ, real damped
sine/cosine terms, the inverse transform, the assembled exact motion and Sylvester's
matrix functions. Exact rational (or symbolic) arithmetic only.
"""
