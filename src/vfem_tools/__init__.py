"""Tools around the solver, not part of it: the benchmark (``vfem bench``, ``vfem study``) and
the CalculiX writer and runner for comparisons. The core (mesh, bodies, contact, solver, io)
never imports this package; the command line does, for its ``bench`` and ``study`` commands.
"""
