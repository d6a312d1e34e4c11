"""The face studies of the 3D models: the α sweep of the dual bases, the √2 families, edge
dropping, the elastic bodies on the face, and their tables."""
