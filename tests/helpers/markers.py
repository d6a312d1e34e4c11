"""Whether a ``-m`` expression asks for a marker itself (the opt-in test groups: ``package``,
``machines``)."""


def asked_for(markexpr: str, marker: str) -> bool:
    """Whether ``-m markexpr`` asks for ``marker`` itself: true with it, false without it (``-m
    package`` yes; ``-m "not slow"`` no, though it does not deselect these tests)."""
    if not markexpr:
        return False
    try:
        from _pytest.mark.expression import Expression
    except ImportError:  # pytest's parser moved: the plain reading
        return marker in markexpr and f"not {marker}" not in markexpr
    expr = Expression.compile(markexpr)
    return expr.evaluate(lambda name, **kw: name == marker) and not expr.evaluate(lambda name, **kw: False)
