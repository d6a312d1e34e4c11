"""The one exception type users see for bad input."""


class InputError(ValueError):
    """Bad user input: names the offending key and the values it accepts."""

    def __init__(self, key: str, allowed: str, got=None):
        self.key, self.allowed, self.got = key, allowed, got
        got_txt = "" if got is None else f" (got {got!r})"
        super().__init__(f"invalid {key}{got_txt}: expected {allowed}")
