"""Any Python value anywhere in a config dict gives a result or a one-line ValueError naming a
field, never a crash (issue 36 item 2): a property test over random values. Needs hypothesis
(`pip install hypothesis`; CI installs it); without it the module is skipped, and pytest's
summary counts the skip (`-rs` prints why)."""

import numpy as np
import pytest

pytest.importorskip("hypothesis", reason="the property test of config dicts needs hypothesis")

from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

import smithwalk  # noqa: E402
from test_config_dict import fresh  # noqa: E402

# Leaves: what a user may put in a dict, good or bad.
LEAVES = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(min_value=-(2**70), max_value=2**70),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=8),
    st.binary(max_size=8),
    st.sampled_from(
        [
            np.float64("nan"),
            np.float32(0.25),
            np.int64(-3),
            np.uint64(2**64 - 1),
            np.bool_(True),
            np.array([0.3, 0.6]),
            np.array([[0.1, 0.2]]),
            np.array(["ggx"]),
            np.datetime64("2026-01-01"),
            complex(1, 2),
            object(),
            "ggx",
            "conductor",
            0.5,
        ]
    ),
)
VALUES = st.recursive(
    LEAVES,
    lambda inner: st.one_of(
        st.lists(inner, max_size=4),
        st.tuples(inner, inner),
        st.dictionaries(st.one_of(st.text(max_size=6), st.sampled_from(["alpha", "kind", "eta"]), st.integers()), inner, max_size=4),
    ),
    max_leaves=20,
)
PLACES = st.sampled_from(
    [
        ("paths",),
        ("seed",),
        ("surface",),
        ("surface", "alpha"),
        ("surface", "ndf"),
        ("material",),
        ("material", "kind"),
        ("material", "eta"),
        ("incident", "theta_deg"),
        ("incident", "phi_deg"),
        ("detector", "cos_theta_bins"),
        ("detector", "max_order"),
        ("extra",),
        ("surface", "extra"),
    ]
)


# 300 examples from a fixed seed (derandomize): the same configs on every run, never flaky.
@settings(max_examples=300, derandomize=True, deadline=None, suppress_health_check=list(HealthCheck))
@given(place=PLACES, value=VALUES)
def test_any_value_anywhere_gives_a_result_or_a_value_error_naming_a_field(place, value):
    config = fresh()
    table = config
    for key in place[:-1]:
        table = table[key]
    table[place[-1]] = value
    try:
        result = smithwalk.run(config)
    except ValueError as error:
        text = str(error)
        assert text.startswith("config <dict> is not valid: "), text
        # One line naming a field: the key that was set, or the table that lacks a key.
        assert "`" in text and "\n" not in text, text
        assert len(text) < 1000, text
    else:
        # Accepted: a valid config, whose numbers are finite.
        assert np.all(np.isfinite(result.energy)), config
