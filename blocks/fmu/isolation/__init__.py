"""FMU instances isolated in processes of their own: the launcher that forks them, the server in each, the client a run talks to."""
