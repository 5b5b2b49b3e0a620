"""Input and output: results files (VTU/PVD, JSON) and figures. The core never imports this."""
