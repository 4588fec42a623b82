"""A pin backend seen through a wrapper: every call passes through to ``inner`` unless the
subclass overrides it (the tests' stand-ins for a design that reads otherwise, or for a
backend that counts its calls)."""


class PinProxy:
    """``inner`` (a ``PinBackend``) with every attribute and call passed through."""

    def __init__(self, inner):
        self.inner = inner

    def __getattr__(self, name):
        return getattr(self.inner, name)

    # Properties are looked up on the class, so they are passed on by hand.
    @property
    def cycle(self):
        return self.inner.cycle

    @property
    def frame_pending(self):
        return self.inner.frame_pending
