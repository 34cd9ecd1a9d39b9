"""The register-map self-test: read what the vendor document defines, write nothing, and say line
by line what matches the register profile in force, what does not, and the likely fix."""
