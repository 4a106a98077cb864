"""Records in and out.  The in-memory record every reader returns (:mod:`.records`), the log
formats read and written (:mod:`.logio`: project logs, truth files, the FRT-DS-ESSO layout, the
channel and unit checks; :mod:`.logwrite`: writing without pandas), a logged trial's rudder rebuilt
from its header (:mod:`.rudder`), a record checked against its ship (:mod:`.shipcheck`), outputs
written all-or-nothing and JSON without NaN (:mod:`.output`), the track and time-history figures
(:mod:`.plots`), the interrupt tests' hook (:mod:`.pausepoint`), the bad-input exception
(:mod:`.errors`) and the one way to run many independent jobs in parallel, locally or on a Dask
cluster (:mod:`.sweep`: every layer above uses it).  A record read wrong, a channel in the wrong unit, a file left behind: start here.
May import :mod:`mmg` only (no other ``trials`` sub-package, no :mod:`ekf`).
"""
