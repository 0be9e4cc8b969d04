"""The Russian texts of the generated board pages (docs/ru/board-<board>.md),
keyed by the names the board map uses (host/orfa/maps/<board>.json).

tools/docgen.py refuses to write the Russian pages when the map has a name
that is missing here (a new status code, driver, register, pin function or
reset cause), so nothing reaches docs/ru/ untranslated. Words follow the
ORFA 0.7.5 manual's (драйвер интроспекции, порты ВВ, сервы, подтягивающие
резисторы ...).
"""

LANGUAGE = "Russian"

#: Status register values, by name (boardmap.STATUS).
STATUS = {
    "OK": "последняя операция выполнена успешно",
    "BAD_LENGTH": "длина записи не подходит регистру",
    "BAD_VALUE": "значение вне допустимого диапазона (номер драйвера больше "
                 "их количества, несуществующий канал, ...)",
    "PIN_BUSY": "вывод, нужный операции, занят другой функцией",
    "NOT_WRITABLE": "в регистр нельзя писать",
    "NOT_READABLE": "регистр нельзя читать",
    "READ_WRAPPED": "чтение интроспекции прошло последний драйвер и продолжилось "
                    "с драйвера 1",
    "NOT_BOUND": "у канала SPI нет линии выбора (chip select)",
    "NO_REGISTER": "фрейм записи назвал регистр, которого нет ни у одного драйвера",
    "DROPPED": "фрейм записи, брошенный мастером, отброшен: из него не применено ничего",
}

#: Protocol error codes, by name (boardmap.ERRORS).
ERRORS = {
    "INTERNAL": "внутренняя ошибка парсера (на практике встречаться не должна)",
    "COMMAND": "неизвестная команда",
    "HEX": "не шестнадцатеричный символ там, где ожидается байт, или байт из "
           "одной цифры",
    "DATA": "ошибочные данные, запрос или ответ длиннее предела, или потерянные "
            "символы",
    "NO_P": "строка кончилась до символа 'P' I2C-запроса",
    "ADDR_NACK": "нет подтверждения адреса (NAck: нет устройства, шина занята, "
                 "регистр нельзя читать)",
    "DATA_NACK": "нет подтверждения байта данных (NAck; или драйвер отверг "
                 "локальную запись)",
}

#: Driver titles, by driver name.
DRIVERS = {
    "intro": "драйвер интроспекции",
    "gpio": "драйвер портов ВВ",
    "spi": "драйвер шины SPI",
    "adc": "драйвер АЦП",
    "motor": "драйвер моторов",
    "servo": "драйвер серв",
    "sys": "системный драйвер (причина сброса, failsafe)",
}

#: One line per register, by (driver, register); GPIO's VALUE_x / MODE_x
#: share the text of VALUE / MODE.
REGISTERS = {
    ("intro", "INTRO"): "записать N, читать записи о драйверах с N-го (0: их количество)",
    ("intro", "STATUS"): "результат последнего обращения к регистру (только чтение)",
    ("gpio", "VALUE"): "уровни линий (чтение); выход или подтяжка (запись [значение][маска])",
    ("gpio", "MODE"): "режимы линий, 1 = выход (запись [режимы][маска])",
    ("spi", "DATA"): "запись [канал][байты]: обмен; чтение: принятые байты",
    ("spi", "CONFIG"): "[канал][порт][линия]: линия выбора; [FF][x][настройки]: шина",
    ("adc", "RC"): "[настройки][маска каналов]",
    ("adc", "RD"): "результаты, 1 или 2 байта на канал (только чтение)",
    ("motor", "PWM1"): "ШИМ 1-го мотора, 0-255",
    ("motor", "PWM2"): "ШИМ 2-го мотора, 0-255",
    ("motor", "DIR1"): "направление 1-го мотора, 0 вперёд, 1 назад",
    ("motor", "DIR2"): "направление 2-го мотора",
    ("servo", "RS"): "маска работающих каналов (чтение; запись ничего не меняет)",
    ("servo", "SP"): "[канал][длительность ст.][длительность мл.] x 1-16, мкс, 0 = выкл.",
    ("sys", "RESET"): "причины сброса с последней очистки; запись маски очищает",
    ("sys", "FAILSAFE"): "защита от потери связи, мс, big-endian, 0 = выкл.",
}

#: Pin functions of the map, for the legend under the pin table.
PIN_FUNCTIONS = {
    "UART_RX": "RXD: приём последовательного порта (к ПК)",
    "UART_TX": "TXD: передача последовательного порта (к ПК)",
    "TWI_SCL": "SCL: тактовая линия шины I2C",
    "TWI_SDA": "SDA: линия данных шины I2C",
    "SPI_SS": "SS: выход, держится высоким, чтобы SPI оставался ведущим",
    "SPI_MOSI": "MOSI: данные SPI к устройству",
    "SPI_MISO": "MISO: данные SPI от устройства",
    "SPI_SCK": "SCK: тактовая линия SPI",
    "MOTOR_PWM": "PWMn: ШИМ мотора n",
    "MOTOR_DIR": "DIRn: направление мотора n",
    "SERVO": "Sn: канал серв n",
    "SERVO_CLK": "CLKn: тактовый вход счётчика CD4017 n",
    "SERVO_RST": "RST: общий сброс счётчиков CD4017",
}

#: Reset causes of the sys driver's RESET register, by name.
RESET_CAUSES = {
    "power": "включение питания (PORF)",
    "external": "вывод RESET (EXTRF)",
    "brownout": "просадка питания (BORF)",
    "watchdog": "сторожевой таймер (WDRF)",
    "jtag": "JTAG (JTRF)",
}

#: Headings, column names and the fixed sentences of the page.
TEXT = {
    "title": "# %s (%s, `BOARD=%s`)\n",
    "intro": ("Тактовая частота %.4f МГц; последовательный порт USART%d; собственный "
              "(локальный) адрес шлюза `%02X` (7-битный 0x%02X); деталь avrdude `%s`, "
              "фьюзы %s.\n"),
    "drivers": "## Драйверы (в порядке интроспекции)\n",
    "drivers_head": "| № | UID | драйвер | версия | регистры |",
    "gpio_ports": "порты %s",
    "registers": "## Карта регистров\n",
    "registers_head": "| регистр | драйвер | имя | назначение |",
    "limits": ("Пределы: запрос %d символов, ответ %d; длительность импульса серв %d-%d мкс, "
               "%d троек за одну запись, %s; SPI: %s, %s за обмен; "
               "FAILSAFE до %d мс.\n"),
    "pins": "## Выводы\n",
    "pins_head": "| порт | 7 | 6 | 5 | 4 | 3 | 2 | 1 | 0 |",
    "pins_note": ("IO = линия драйвера портов ВВ (порты %s), когда её не держит другая "
                  "функция; ADn = канал АЦП n%s. Остальные обозначения:\n"),
    "pins_note_4017": " (здесь каналы серв идут через счётчики CD4017)",
    "status": "## Значения регистра статуса\n",
    "status_head": "| код | имя | значение |",
    "errors": "## Коды ошибок протокола\n",
    "errors_head": "| ответ | имя | значение |",
    "resets": "## Причины сброса (регистр RESET системного драйвера)\n",
    "resets_head": "| бит | имя | причина |",
    "see": ("Подробнее о каждом регистре: [protocol.md](protocol.md) (по-русски), "
            "[../registers.md](../registers.md) (по-английски). English: "
            "[../board-%s.md](../board-%s.md).\n"),
}


def plural(n: int, one: str, few: str, many: str) -> str:
    """`n` with the Russian noun form its number takes: 1 канал, 4 канала, 16 каналов."""
    if n % 10 == 1 and n % 100 != 11:
        word = one
    elif 2 <= n % 10 <= 4 and not 12 <= n % 100 <= 14:
        word = few
    else:
        word = many
    return "%d %s" % (n, word)


def channels(n: int) -> str:
    return plural(n, "канал", "канала", "каналов")


def nbytes(n: int) -> str:
    return plural(n, "байт", "байта", "байт")
