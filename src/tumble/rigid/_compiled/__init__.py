"""The compiled (numba) twins of the rigid-body references, each module beside the one it
mirrors: :mod:`.charts` (:mod:`tumble.rigid.charts`), :mod:`.flows` and :mod:`.exact_flow`
(:mod:`tumble.rigid.geometric`), on :mod:`.base` (the run's data, records, 3-vector helpers
and the binding of a loop template to a family's functions). Importing any of them loads
numba; the Python side imports them only when a compiled run needs them.
"""
