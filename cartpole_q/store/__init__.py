"""What training leaves on disk: atomic files, run directories, checkpoints, videos."""
