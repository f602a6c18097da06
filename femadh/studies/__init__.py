"""Studies over many solves: mesh convergence and accuracy vs time (:mod:`.convergence`), the
smooth-sphere LJ regime map vs the Tabor parameter (:mod:`.regime`)."""
