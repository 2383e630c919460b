"""See the mechanism: the animated 3-D scene of a run (:mod:`.scene`), written as one offline
HTML page (:mod:`.html`), glTF (:mod:`.gltf`) or VTK files for ParaView (:mod:`.vtk`)."""

from drivedyn.viewer.scene import Scene, build_scene

__all__ = ["Scene", "build_scene"]
