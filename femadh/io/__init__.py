"""Outputs: csv/json writers (:mod:`.writers`), VTK for ParaView/PyVista (:mod:`.vtk`),
figures (:mod:`.plots`)."""
