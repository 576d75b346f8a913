"""A config dict of any Python values gives a result or a Python exception, never a crash
(issue 36 item 2: a dict that holds itself, or one nested 10 000 deep, crashed the
interpreter), and a seed may be any integer from 0 to 2^64 - 1, Python's or numpy's. The
property test over random values is in test_config_property.py (it needs hypothesis)."""

import numpy as np
import pytest

import smithwalk

# A small valid config: two photons per case over one bin, so that a random config that happens
# to be valid runs in a millisecond.
BASE = {
    "paths": 2,
    "surface": {"alpha": 0.5},
    "material": {"kind": "conductor"},
    "incident": {"theta_deg": 30},
    "detector": {"cos_theta_bins": 1, "phi_bins": 1, "max_order": 1},
}


def fresh():
    """A deep copy of BASE."""
    return {k: dict(v) if isinstance(v, dict) else v for k, v in BASE.items()}


def check_refused(config, field):
    """`config` is refused with a ValueError that names `field`, in one line."""
    with pytest.raises(ValueError) as error:
        smithwalk.run(config)
    text = str(error.value)
    assert text.startswith("config <dict> is not valid: "), text
    assert f"`{field}" in text and "\n" not in text, text
    return text


def test_a_dict_that_holds_itself_is_refused():
    config = fresh()
    config["surface"]["self"] = config
    text = check_refused(config, "surface.self.surface.self")
    assert "nested at most 16 deep" in text and "holds itself" in text, text
    looped = fresh()
    looped["incident"]["theta_deg"] = [30]
    looped["incident"]["theta_deg"].append(looped["incident"]["theta_deg"])
    check_refused(looped, "incident.theta_deg[1][1]")


def test_a_dict_nested_10000_deep_is_refused():
    config = fresh()
    inner = config["surface"]
    for _ in range(10_000):
        inner["a"] = {}
        inner = inner["a"]
    check_refused(config, "surface.a.a.a")
    deep = [0.5]
    for _ in range(100_000):
        deep = [deep]
    check_refused({**fresh(), "surface": {"alpha": deep}}, "surface.alpha[0][0]")


@pytest.mark.parametrize(
    "seed", [2**64 - 1, np.uint64(2**64 - 1), 2**63, np.uint64(2**63), np.int64(2**63 - 1), 0, np.uint8(7)]
)
def test_every_seed_of_the_range_is_accepted_as_argument_and_in_the_dict(seed):
    by_argument = smithwalk.run(fresh(), seed=seed)
    in_dict = smithwalk.run({**fresh(), "seed": seed})
    assert by_argument.info["seed"] == in_dict.info["seed"] == int(seed)
    # The same seed gives the same numbers either way.
    assert np.array_equal(by_argument.energy, in_dict.energy)


@pytest.mark.parametrize("seed", [2**64, -1, np.int64(-1)])
def test_a_seed_beyond_the_range_is_refused(seed):
    with pytest.raises(ValueError, match=r"`seed` = -?\d+ is not allowed"):
        smithwalk.run(fresh(), seed=seed)
    with pytest.raises(ValueError, match=r"`seed`"):
        smithwalk.run({**fresh(), "seed": seed})
