"""Multiplier spaces on the face, one construction per module: tensor products of the segment's
spaces (``tensor``), nodal spaces on quadrilateral cells (``cellwise``), P_s on Kuhn triangles
(``triangles``) and on general triangulations (``unstructured``), TRI6 (``tri6``), a face clipped
at x = L (``clipped``); the reference elements and dual bases they share."""
