/* Translation unit of the image target itself; everything else comes from libraries. */
