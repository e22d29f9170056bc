"""The figures of finished runs, by subject (packings, forces, expansion, structure, tracer,
adhesion, conventions, the EPD and study-file studies); :mod:`.plan` decides which figures a
result set gets, apart from the drawing."""
