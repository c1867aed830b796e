"""``Like(kind, **fields)``: equal to any ``kind`` whose named fields equal those given (``pytest.approx`` works
there), for commands that check their fields when made and so cannot hold an ``approx`` themselves."""


class Like:
    def __init__(self, kind, **fields):
        self.kind, self.fields = kind, fields

    def __eq__(self, other):
        return type(other) is self.kind and all(getattr(other, k) == v for k, v in self.fields.items())

    def __repr__(self):
        return f"Like({self.kind.__name__}, {', '.join(f'{k}={v!r}' for k, v in self.fields.items())})"
