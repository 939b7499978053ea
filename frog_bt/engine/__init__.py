"""What a tour runs on: the board, snapshot, actions, journal, context and Core."""
