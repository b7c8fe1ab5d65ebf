"""Recording sessions on the physics: the instrumented arm (controller, sensors and faults on the
simulator), the session recorder, and measured fault effect sizes."""
