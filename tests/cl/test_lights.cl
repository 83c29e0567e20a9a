// (filled in by the BSDF / light sampling tests)
