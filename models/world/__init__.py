"""The world: the warehouse (walls, shelves, starts), its shelf layouts, moving obstacles."""
