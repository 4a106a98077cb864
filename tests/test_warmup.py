"""The warm-up of numba's cache (:mod:`trials.cli.warmup`): each group must compile the specialisation
the real work then uses (a warm-up that compiles another one only costs time), and the compiled
passes must not split into several specialisations by how they are called (a literal constant, a
read-only or strided array each compile the whole pass again on a cold cache)."""
from __future__ import annotations

import numpy as np
import pytest

from mmg.ship import load_ship


def test_filter_warmup_compiles_the_specialisation_a_real_pass_uses():
    """``mmg estimate`` with a cold cache compiles the filter in a child from a dummy record
    (trials.cli.warmup.warm_filter); that is only worth it if a real pass then needs no other one."""
    from ekf.filter import filter_kernel
    from mmg import estimate, simulate, zigzag
    from trials.cli.warmup import warm_filter

    def passes():              # the compiled pass itself (reference=None), not the tests' reference=True one
        return {sig for sig in filter_kernel.signatures if "omitted" in str(sig[-1])}

    warm_filter()
    before = passes()
    ship = load_ship("esso_osaka")
    estimate(simulate(zigzag(ship, rudder="20 deg", heading="20 deg", speed="10 kn", duration="120 s")), seed=1)
    assert len(before) == 1 and passes() == before


def test_background_compile_is_stopped_when_the_work_fails():
    from trials.cli.warmup import compiling_in_background

    with pytest.raises(RuntimeError):
        with compiling_in_background("filter") as compiled:
            proc = compiled.process
            raise RuntimeError("the inputs were bad")
    assert proc.poll() is not None                        # stopped, not left running
    with compiling_in_background("filter", when=False) as compiled:
        assert compiled.process is None
        compiled()                                        # nothing to wait for


def test_replay_warmup_covers_read_only_and_strided_inputs():
    """A record's columns come from pandas (read-only, strided): the replay must still run the one
    specialisation the warm-up compiled."""
    from mmg.model import pack
    from mmg.replay import ReplayInputs, _replay, replay
    from trials.cli.warmup import warm_replay

    warm_replay()
    before = set(_replay.signatures)
    t, delta = np.arange(0.0, 3.0, 0.1), np.zeros(30)              # read-only, as pandas hands them out
    t.setflags(write=False)
    delta.setflags(write=False)
    n = np.column_stack([t, np.full(30, 9.0)])[:, 1]               # a strided view
    assert not n.flags.c_contiguous
    out = replay(pack(load_ship("esso_osaka_3m")), ReplayInputs(t, delta, n), np.array([0.3, 0, 0, 0, 0, 0.0]))
    assert np.isfinite(out).all()
    assert len(before) == 1 and set(_replay.signatures) == before


def test_join_waits_for_one_group_and_the_exit_for_all():
    """join(group) returns once that group is compiled (the child goes on with the next); a group
    the child never reports (here: not asked for) does not hang the caller; the with-exit waits."""
    from trials.cli.warmup import compiling_in_background

    with compiling_in_background("replay", "replay", when=True) as compiled:
        compiled("replay")
        proc = compiled.process
        compiled("not-a-group")                            # the child ended without it: returns
        assert proc.poll() is not None
    assert proc.returncode == 0
