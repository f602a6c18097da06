"""Running a scene: build its problem, solve it, stream results to disk, draw its figures.
Contact scenes (:mod:`.contact`) and meniscus scenes (:mod:`.meniscus`)."""
