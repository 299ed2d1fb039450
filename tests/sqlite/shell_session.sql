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
CREATE VIRTUAL TABLE ships USING loci_fleet(id, t, x, y, vx, vy);
INSERT INTO ships VALUES
  (1, 0, 0, 0, 10, 0),
  (2, 0, 1000, 50, -10, 0),
  (3, 30, 500, 400, 0, -10),
  (1, -60, -700, 0, 10, 0);
SELECT id, t, x FROM ships;
SELECT id, x, y FROM loci_fleet_window('ships', 400, -100, 600, 100, 50);
SELECT id FROM loci_fleet_window('ships', -1000, -100, 0, 100, -30);
SELECT id_a, id_b, tcpa, dcpa, round(t_enter, 1), round(t_exit, 1)
  FROM loci_conflicts('ships', 100, 120);
SELECT id, round(distance, 1) FROM loci_fleet_nearest('ships', 500, 10, 2, 60);
SELECT loci_check('ships');
