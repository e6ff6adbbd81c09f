"""One domain rule per friction parameter, the same in Python and C (issue 39): the core's table
(``core/include/thermofriction/domains.h``, exported by the binding as ``FRICTION_DOMAINS``) against the package's
(``models/domains.py: PARAMETER_DOMAIN``), rule by rule. The two vocabularies differ only in spelling, and in one
thing by design: C checks a value only where the model uses it (its ``when``: a Stribeck term where fs != fc, the
smoothed sign of the offset form), Python holds every value a model file gives to its rule, so there Python's rule
is the same rule applied everywhere."""

import pytest

from thermofriction import _bridge
from thermofriction.models import FRICTION_MODELS
from thermofriction.models.domains import PARAMETER_DOMAIN

#: C's (rule, other) -> Python's rule code; "positive-or-absent" is C's 0 for "not given", Python's None
SPELLING = {("positive", None): "positive", ("non-negative", None): "nonnegative",
            ("positive-or-absent", None): "positive"}


def _python_rule(rule, other, parameter):
    if rule == "at-least":
        return f"ge:{other}"
    if rule == "below-deflection":
        return f"below:{other}/sigma0"
    if parameter == "vs" and rule == "positive":  # (C's 'when: stribeck' is part of Python's rule for vs)
        return "positive_if:fs!=fc"
    return SPELLING[(rule, other)]


ROWS = [(m, row) for m, rows in _bridge.FRICTION_DOMAINS.items() for row in rows]


@pytest.mark.parametrize("model,row", ROWS, ids=[f"{m}-{r[0]}" for m, r in ROWS])
def test_each_c_rule_is_the_python_rule(model, row):
    parameter, rule, other, when = row
    assert when in ("always", "stribeck", "offset-form")
    assert PARAMETER_DOMAIN[parameter] == _python_rule(rule, other, parameter), (model, row)


@pytest.mark.parametrize("model", sorted(FRICTION_MODELS))
def test_every_scalar_parameter_of_a_model_has_a_c_rule(model):
    """Each of the model's scalar parameters the core reads is in the core's table for that model (the arrays of
    GMS, k and w, and the negative side and ripple, checked on their own values by the same rows, are not)."""
    cls = FRICTION_MODELS[model]
    c_rows = {r[0] for r in _bridge.FRICTION_DOMAINS[cls.description.c_id]}
    scalars = {f for f in cls.required if f not in cls.description.arrays}
    assert scalars <= c_rows, scalars - c_rows
    assert c_rows <= set(PARAMETER_DOMAIN)


def test_the_check_finds_a_disagreement():
    """The comparison itself: a C rule spelled as another Python rule is caught."""
    assert _python_rule("non-negative", None, "sigma1") == PARAMETER_DOMAIN["sigma1"]
    assert _python_rule("positive", None, "sigma1") != PARAMETER_DOMAIN["sigma1"]
