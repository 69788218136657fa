"""The compiler behind one seam: the RK4 loop, kernel generation and caching, JIT settings, vector math and SIMD lanes."""
