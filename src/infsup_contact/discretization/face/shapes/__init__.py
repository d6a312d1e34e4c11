"""discretization.face.shapes.square."""
