"""Which branches are born there: the pear branches switched at a pitchfork, their mirror images, the pear branch a broken symmetry disconnects, and the energy landscape near a pitchfork."""
