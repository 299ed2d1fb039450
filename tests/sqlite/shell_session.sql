.load @EXTENSION@
CREATE VIRTUAL TABLE parks USING loci_rtree(id, minx, maxx, miny, maxy, +name);
INSERT INTO parks VALUES
  (1, 12.50, 12.60, 55.60, 55.70, 'Faelledparken'),
  (2, 12.55, 12.58, 55.68, 55.69, 'Kongens Have'),
  (3, 10.20, 10.30, 56.10, 56.20, 'Riis Skov');
SELECT id, name FROM parks
 WHERE minx <= 12.57 AND maxx >= 12.56 AND miny <= 55.685 AND maxy >= 55.684 ORDER BY id;
SELECT id, round(distance, 3) FROM loci_nearest('parks', 10.0, 56.0, 2);
SELECT loci_check('parks');
