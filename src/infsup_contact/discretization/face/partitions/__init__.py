"""discretization.face.partitions.tensor_grid."""
