"""Writing files: DXF cutting drawings, meshes (STL, GLB, 3MF), atomic writes."""
