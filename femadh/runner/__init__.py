"""Running a scene: build its problem, solve it, stream results to disk, draw its figures.
:mod:`.run` (the entry for every kind) hands contact scenes to :mod:`.contact` and meniscus
scenes to :mod:`.meniscus`; both live one :mod:`.lifecycle` and return a :mod:`.result`."""
