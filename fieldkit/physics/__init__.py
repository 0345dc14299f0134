"""Rockfall physics as pure, vectorised functions (thesis ch. 3-8, appendices B-D).

Numbers in, numbers out: no I/O, no state, SI units. Nothing here imports from the rest
of fieldkit. Each docstring cites the thesis equation it implements.
"""
