"""PyCRAM: concurrent, reactive plans for mobile manipulation robots."""
