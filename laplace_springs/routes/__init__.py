"""The routes: each implements the result contract of :mod:`laplace_springs.solution`.

``exact`` (exact partial fractions), ``modal`` (float64 modes with a measured bound) and
``certified`` (certified poles, ball arithmetic). :mod:`laplace_springs.policy` decides
which one solves a scene; :func:`laplace_springs.solve` builds it.
"""
