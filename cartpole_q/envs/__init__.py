"""Making Gymnasium environments and their compiled twins."""
