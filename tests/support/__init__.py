"""What the tests (and the benchmarks) need besides the product: call spies, the app built headless, the app served
in a subprocess, and the process-leak checks. Nothing here ships in the wheel; the product never imports it."""
