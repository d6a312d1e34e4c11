"""Linear algebra the libraries leave on one core: threaded sparse × dense sandwiches and the
face series' reordering (:mod:`.threaded`)."""
