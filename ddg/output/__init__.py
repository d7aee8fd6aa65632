"""What a run writes and reads back: run folders (path.csv, summary.json, centerline.csv),
ParaView frames, and signal handling so that an interrupted run keeps what it computed."""
