"""Point-cloud experts: cloud generation, filters, normals, the support plane, clustering, pose, shape, size."""
