"""Stage 3, numbers: evaluation of exact terms (float64 and mpmath), the float64 modal route,
the certified route (exact polynomials, ball arithmetic), evaluation times.
"""
