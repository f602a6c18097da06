"""What every kind of scene shares: a validated copy with some keys changed."""


class Replaceable:
    """Mixin of the scene classes: :meth:`replace` (validated by :func:`replace_scene`)."""

    def replace(self, changes=None, /, *, si=False, **kw):
        """A new scene with keys changed, validated like a file: ``changes`` maps dotted keys
        to values (``{"sphere.radius": "1 um", "effects.asperity_gap.sigma": "0.5 nm"}``);
        keywords use ``__`` for the dots (``sphere__radius="1 um"``).

        A dimensional value needs its unit, as in a file (``0.6`` for a length is refused
        with the file's one-line error); ``si=True`` takes bare numbers as SI (code that
        holds SI floats, e.g. a fit's parameter vector). Raises SceneError for any bad key
        or value (a key that is not a dotted string included)."""
        from . import replace_scene

        return replace_scene(self, changes, kw, si)

    @property
    def as_given(self):
        """The scene's keys as the user gave them (``raw``; a variant's, e.g. an adaptive
        trial's: the keys of the scene it was made from). A run folder records them, so that
        a ``--resume`` of a changed scene names the keys that changed."""
        return getattr(self, "given", None) or self.raw
