"""The face Γ shapes of the 3D models: the square (tensor cells), its triangulations, the serendipity face, the cylinder and its projection coupling."""
