"""Tools for testing rockjit itself: the seeded stress suite (:mod:`.stress`)."""
