"""Industry test protocols (Euro NCAP AEB Car-to-Car, UN R152) as shipped test suites."""
