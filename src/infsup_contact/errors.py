"""The one exception type users see for bad input."""


class InputError(ValueError):
    """Bad user input: names the offending key and the values it accepts."""

    def __init__(self, key: str, allowed: str, got=None):
        self.key, self.allowed, self.got = key, allowed, got
        got_txt = "" if got is None else f" (got {got!r})"
        super().__init__(f"invalid {key}{got_txt}: expected {allowed}")

    def __reduce__(self):
        # pickled as it is (a worker process's error reaches the parent whole): its args and
        # attributes, whatever the constructor of a subclass takes
        return _restored, (type(self), self.args, dict(self.__dict__))


def _restored(cls, args, state):
    """An :class:`InputError` (or subclass) from its pickled args and attributes."""
    error = cls.__new__(cls, *args)
    error.args = args
    error.__dict__.update(state)
    return error


C_RANGE = (1e-150, 1e150)
"""Allowed membrane prestress c_i. The interface operator scales like 1/c_i and the energy like
c_i, and products of two such numbers must stay normal doubles (|log10 c| <= 150 keeps c² and
1/c² inside 1e±300). c = inf — a rigid body — is the obstacle limit, which is not modelled: for
β_h its value is the column ``beta_v1_zero`` (the constant of (5.10), v1 = 0)."""
C_ALLOWED = (f"a finite number in [{C_RANGE[0]:g}, {C_RANGE[1]:g}] (c = inf, a rigid body, is the "
             "obstacle limit, not modelled; for beta_h read beta_v1_zero)")


def check_prestress(key: str, value) -> float:
    """c1 or c2 as a float in :data:`C_RANGE`; :class:`InputError` naming ``key`` otherwise."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(key, C_ALLOWED, got=value) from None
    if isinstance(value, bool) or not C_RANGE[0] <= v <= C_RANGE[1]:  # NaN fails both comparisons
        raise InputError(key, C_ALLOWED, got=value)
    return v
